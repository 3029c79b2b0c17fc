//! Each window rule's pass or fail, alone (the proposed scene's value) and, with the existing
//! scene's value ("former"), by BRE 209's relative tests:
//! - VSC (2.2.7): a window is affected when its VSC is below [`VSC_TARGET`] % *and* below
//!   [`FORMER_RATIO`] × its former value;
//! - APSH/WPSH (3.2.11): affected when it receives below [`APSH_TARGET`] % of annual or below
//!   [`WPSH_TARGET`] % of winter probable sunlight hours, *and* below 0.8 × its former value in
//!   either period, *and* loses more than [`APSH_LOSS`] points of annual probable sunlight hours;
//! - GB 50180: the hours reach the required hours (no relative test: the standard has none);
//! - the No-Sky Line (a room's, not a window's): the share of its working plane that sees sky
//!   not below [`FORMER_RATIO`] × its former share.
//!
//! Values within [`TOLERANCE`] of a threshold count as reaching it (the report prints one decimal).

/// BRE's VSC target, %.
pub const VSC_TARGET: f64 = 27.0;
/// BRE's "not less than 0.8 times its former value".
pub const FORMER_RATIO: f64 = 0.8;
/// BRE's APSH target, % of annual probable sunlight hours.
pub const APSH_TARGET: f64 = 25.0;
/// BRE's WPSH target, % of annual probable sunlight hours.
pub const WPSH_TARGET: f64 = 5.0;
/// BRE's largest acceptable annual loss, points of % APSH.
pub const APSH_LOSS: f64 = 4.0;
/// Slack for a value computed to equal its threshold.
pub const TOLERANCE: f64 = 1e-9;

/// One point's verdict.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Verdict {
    /// Whether the rule passes (the absolute test, or with a former value the relative one).
    pub passes: bool,
    /// The absolute test alone.
    pub absolute: bool,
    /// The relative test alone (`None` without a former value).
    pub relative: Option<bool>,
}

/// The ratio now / before; `None` without a former value or where it was 0.
pub fn ratio(now: f64, before: Option<f64>) -> Option<f64> {
    before.filter(|&b| b > 0.0).map(|b| now / b)
}

fn at_least(value: f64, threshold: f64) -> bool {
    value + TOLERANCE >= threshold
}

/// BRE 209's VSC test for a window with `now` % and, if it existed, `before` %.
pub fn vsc(now: f64, before: Option<f64>) -> Verdict {
    let absolute = at_least(now, VSC_TARGET);
    let relative = before.map(|b| at_least(now, FORMER_RATIO * b));
    Verdict { passes: absolute || relative == Some(true), absolute, relative }
}

/// BRE 209's sunlight test for a window with `apsh`/`wpsh` % now and, if it existed, before.
pub fn apsh(apsh: f64, wpsh: f64, before: Option<(f64, f64)>) -> Verdict {
    let absolute = at_least(apsh, APSH_TARGET) && at_least(wpsh, WPSH_TARGET);
    let relative = before.map(|(a0, w0)| {
        let reduced = !at_least(apsh, FORMER_RATIO * a0) || !at_least(wpsh, FORMER_RATIO * w0);
        let lost = a0 - apsh > APSH_LOSS + TOLERANCE;
        !(reduced && lost)
    });
    Verdict { passes: absolute || relative == Some(true), absolute, relative }
}

/// BRE 209's 25° pre-check: nothing in the perpendicular section above [`super::bre_lines::LINE_25_DEG`].
pub fn line_25(angle_deg: f64) -> Verdict {
    let absolute = angle_deg <= super::bre_lines::LINE_25_DEG + TOLERANCE;
    Verdict { passes: absolute, absolute, relative: None }
}

/// BRE 209's 45° pre-check: nothing within both 45° lines.
pub fn line_45(within: bool) -> Verdict {
    Verdict { passes: !within, absolute: !within, relative: None }
}

/// BRE 209's daylight distribution test (the No-Sky Line) for a room whose working plane sees
/// sky on `now` % of its area and did on `before` %: noticeably worse when reduced below
/// [`FORMER_RATIO`] × its former value (a room that saw none loses nothing). Relative only: the
/// guide sets no share a room must reach.
pub fn no_sky_line(now: f64, before: f64) -> bool {
    at_least(now, FORMER_RATIO * before)
}

/// GB 50180's test: `hours` reach `required`.
pub fn hours(hours: f64, required: f64) -> Verdict {
    let absolute = at_least(hours, required);
    Verdict { passes: absolute, absolute, relative: None }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// BRE 209's worked thresholds, case by case.
    #[test]
    fn the_relative_tests_fail_only_when_every_condition_holds() {
        assert!(vsc(27.0, None).passes && !vsc(26.9, None).passes);
        assert!(vsc(20.0, Some(25.0)).passes, "0.8 × 25 = 20 is kept");
        assert!(!vsc(19.9, Some(25.0)).passes);
        // Below 25 %, below 0.8 × former, but a loss of only 4 points: passes.
        assert!(apsh(16.0, 6.0, Some((20.0, 6.0))).passes);
        // A loss of 5 points, below 0.8 × former: fails.
        assert!(!apsh(15.0, 6.0, Some((20.0, 6.0))).passes);
        // Winter below 5 % and below 0.8 × former, annual loss over 4 points: fails.
        assert!(!apsh(30.0, 3.0, Some((35.0, 5.0))).absolute);
        assert!(!apsh(24.0, 3.0, Some((35.0, 5.0))).passes);
        assert!(apsh(30.0, 5.0, None).passes && !apsh(30.0, 4.9, None).passes);
        assert_eq!(ratio(10.0, Some(0.0)), None);
        assert!(hours(2.0, 2.0).passes && !hours(1.99, 2.0).passes);
        assert!(no_sky_line(40.0, 50.0) && !no_sky_line(39.9, 50.0) && no_sky_line(0.0, 0.0));
    }
}
