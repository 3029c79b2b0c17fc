//! Each window's own 满窗 width for GB 50180 ([`super::gb50180`]), read from a CSV of
//! `receiver,width` rows (the window's receiver name, its sill's width in metres), instead of one
//! width for every window: windows differ, and the rule asks for the sun over each one's whole
//! sill. A name matches every receiver of that name; every studied point's window needs a row.
//!
//! Bad input is refused naming the file, the line and the reason: another header, a row that is
//! not a name and a number, a width outside (0, [`MAX_WIDTH`]] m, a name given twice or not a
//! receiver of the model; and naming the file and the window, a studied window without a row.

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

/// Each of `points`' widths (m, in their order) from the CSV `text` (`file_label` names it in
/// errors), by the name of the receiver each point lies on in `scene`.
pub fn sill_widths(scene: &Scene, points: &Points, file_label: &str, text: &str) -> Result<Vec<f64>> {
    let by_name = read(scene, file_label, text)?;
    points
        .receivers
        .iter()
        .enumerate()
        .map(|(i, &r)| {
            let name = scene.receivers.get(r as usize).map_or("", |r| r.name.as_str());
            by_name.get(name).copied().ok_or_else(|| {
                Error::model(
                    file_label,
                    format!("no row gives the width of window '{name}' (point {}): give one for each window studied", i + 1),
                )
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
        if !valid(width) {
            return Err(Error::object(file_label, at(), format!("width {width} m is not in (0, {MAX_WIDTH}]")));
        }
        if !scene.receivers.iter().any(|r| r.name == name) {
            return Err(Error::object(file_label, at(), format!("'{name}' is not one of the model's chosen receivers (windows)")));
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
