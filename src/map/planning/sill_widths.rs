//! Each window's own 满窗 width for GB 50180 ([`super::gb50180`]), read from a CSV of
//! `receiver,width` rows (the window's receiver name, its sill's width in metres), instead of one
//! width for every window: windows differ, and the rule asks for the sun over each one's whole
//! sill. A name matches every receiver of that name; every studied point's window needs a row.
//!
//! Bad input is refused naming the file, the line and the reason: another header, a row that is
//! not a name and a number, a width outside (0, [`MAX_WIDTH`]] m, a name given twice or not a
//! receiver of the model; and naming the file and the window, a studied window without a row.
//! [`named_widths`] takes the same widths by name (the JS API's object), refused the same way
//! naming `window_widths`. [`WholeWindow`] reads what `window_width` asks: one width for every
//! window, or each window's own sill measured from its geometry ([`super::sill_lines`]).

use std::collections::HashMap;

use crate::error::{Error, Result};
use crate::map::Points;
use crate::scene::Scene;

/// The widest sill a width may give (m), as `--window-width` takes.
pub const MAX_WIDTH: f64 = 20.0;

/// Whether `width` (m) is a sill width the rule takes: finite, in (0, [`MAX_WIDTH`]].
pub fn valid(width: f64) -> bool {
    width.is_finite() && width > 0.0 && width <= MAX_WIDTH
}

/// What `window_width` asks for the 满窗 rule.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum WholeWindow {
    /// One sill width (m) for every window, centred on each point.
    Width(f64),
    /// Each window's own sill line, measured from its geometry ([`super::sill_lines`]).
    Sill,
}

impl WholeWindow {
    /// Reads `sill` or a width in metres (in (0, [`MAX_WIDTH`]]); refuses another, naming
    /// `window_width`.
    pub fn parse(text: &str) -> Result<Self> {
        let text = text.trim();
        if text.eq_ignore_ascii_case("sill") {
            return Ok(Self::Sill);
        }
        match text.parse::<f64>() {
            Ok(width) if valid(width) => Ok(Self::Width(width)),
            Ok(width) => Err(Error::argument("window_width", format!("{width} m is not in (0, {MAX_WIDTH}]"))),
            Err(_) => Err(Error::argument("window_width", format!("'{text}' is neither a width in metres nor sill (each window's own)"))),
        }
    }

    /// The one width, if one was given.
    pub fn width(self) -> Option<f64> {
        match self {
            Self::Width(width) => Some(width),
            Self::Sill => None,
        }
    }
}

/// Each of `points`' widths (m, in their order) from the CSV `text` (`file_label` names it in
/// errors), by the name of the receiver each point lies on in `scene`.
pub fn sill_widths(scene: &Scene, points: &Points, file_label: &str, text: &str) -> Result<Vec<f64>> {
    let by_name = read(scene, file_label, text)?;
    per_point(scene, points, &by_name, |reason| Error::model(file_label, reason))
}

/// Each of `points`' widths (m, in their order) from `(window name, width)` pairs, refused as
/// [`sill_widths`] refuses a file's rows, naming `window_widths`.
pub fn named_widths(scene: &Scene, points: &Points, widths: &[(String, f64)]) -> Result<Vec<f64>> {
    let mut by_name = HashMap::new();
    for (name, width) in widths {
        let reason = match checked(scene, name, *width) {
            Err(reason) => Some(format!("'{name}': {reason}")),
            Ok(()) => by_name.contains_key(name).then(|| format!("'{name}' is given a width twice")),
        };
        if let Some(reason) = reason {
            return Err(Error::argument("window_widths", reason));
        }
        by_name.insert(name.clone(), *width);
    }
    if by_name.is_empty() {
        return Err(Error::argument("window_widths", "no widths given"));
    }
    per_point(scene, points, &by_name, |reason| Error::argument("window_widths", reason))
}

/// Why `width` for the window `name` is refused, if it is: outside (0, [`MAX_WIDTH`]], or not a
/// chosen receiver's name.
fn checked(scene: &Scene, name: &str, width: f64) -> std::result::Result<(), String> {
    if !valid(width) {
        return Err(format!("width {width} m is not in (0, {MAX_WIDTH}]"));
    }
    if !scene.receivers.iter().any(|r| r.name == name) {
        return Err("not one of the model's chosen receivers (windows)".into());
    }
    Ok(())
}

/// Each point's width by its window's name; a point whose window has none is refused by
/// `error(reason)`.
fn per_point(scene: &Scene, points: &Points, by_name: &HashMap<String, f64>, error: impl Fn(String) -> Error) -> Result<Vec<f64>> {
    points
        .receivers
        .iter()
        .enumerate()
        .map(|(i, &r)| {
            let name = scene.receivers.get(r as usize).map_or("", |r| r.name.as_str());
            by_name.get(name).copied().ok_or_else(|| {
                error(format!("no row gives the width of window '{name}' (point {}): give one for each window studied", i + 1))
            })
        })
        .collect()
}

/// The rows of the CSV: width by receiver name.
fn read(scene: &Scene, file_label: &str, text: &str) -> Result<HashMap<String, f64>> {
    let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty());
    let header: Vec<String> = lines.next().map(|(_, l)| l.split(',').map(|f| f.trim().to_ascii_lowercase()).collect()).unwrap_or_default();
    if header != ["receiver", "width"] {
        return Err(Error::model(file_label, format!("the header is '{}', expected 'receiver,width'", header.join(","))));
    }
    let mut widths = HashMap::new();
    for (index, line) in lines {
        let at = || format!("line {}", index + 1);
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        let [name, width] = fields[..] else {
            return Err(Error::object(file_label, at(), format!("'{}' is not a receiver's name and a width", line.trim())));
        };
        let width: f64 = width.parse().map_err(|_| Error::object(file_label, at(), format!("width '{width}' is not a number")))?;
        if let Err(reason) = checked(scene, name, width) {
            let reason = if valid(width) { format!("'{name}' is {reason}") } else { reason };
            return Err(Error::object(file_label, at(), reason));
        }
        if widths.insert(name.to_string(), width).is_some() {
            return Err(Error::object(file_label, at(), format!("'{name}' is given a width twice")));
        }
    }
    if widths.is_empty() {
        return Err(Error::model(file_label, "no widths after the header"));
    }
    Ok(widths)
}
