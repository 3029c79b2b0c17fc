//! EnergyPlus IDF text reader: splits an input file into objects of positional fields.
//!
//! Owns the IDF syntax only (what a class, a field, a comment and an object's end are), not the
//! meaning of any class: `!` starts a comment to the end of the line (`!-` included), fields are
//! separated by `,`, an object ends at `;`, whitespace and newlines between tokens are free and
//! class names compare case-insensitively. There is no quoting in IDF, so a `!` is always a comment.
//! The geometry in the objects is read by [`super::building`]; epJSON files reach the same
//! [`IdfObject`] form through [`super::epjson`].

use crate::error::{Error, Result};

/// One object of an input file: its class and its fields in IDD order.
#[derive(Debug, Clone, PartialEq)]
pub struct IdfObject {
    /// The class as written (e.g. `BuildingSurface:Detailed`); compare with [`IdfObject::is`].
    pub class: String,
    /// The fields after the class, trimmed; the first is usually the name. Empty fields are kept
    /// as `""` so positions stay those of the IDD.
    pub fields: Vec<String>,
    /// 1-based line where the object starts (its class name).
    pub line: usize,
    /// 1-based line of its terminating `;` (for epJSON objects, the same as `line`).
    pub end_line: usize,
}

impl IdfObject {
    /// Whether this object is of `class` (EnergyPlus class names are case-insensitive).
    pub fn is(&self, class: &str) -> bool {
        self.class.eq_ignore_ascii_case(class)
    }

    /// Field `i` (0-based, after the class), or `""` when the object is shorter: EnergyPlus
    /// treats omitted trailing fields as blank.
    pub fn field(&self, i: usize) -> &str {
        self.fields.get(i).map_or("", String::as_str)
    }

    /// The first field when it is not blank (most classes name their objects there).
    pub fn name(&self) -> Option<&str> {
        self.fields.first().map(String::as_str).filter(|n| !n.is_empty())
    }

    /// `Class 'Name' (line N)` (or `Class (line N)` for classes without a name field), for messages.
    pub fn label(&self) -> String {
        let unnamed = UNNAMED_CLASSES.iter().any(|c| self.is(c));
        object_label(&self.class, self.name().filter(|_| !unnamed), self.line)
    }
}

/// Common classes whose first field is not a name (their objects are labelled by class alone).
const UNNAMED_CLASSES: [&str; 15] = [
    "Version",
    "SimulationControl",
    "Timestep",
    "ShadowCalculation",
    "GlobalGeometryRules",
    "GeometryTransform",
    "Compliance:Building",
    "HeatBalanceAlgorithm",
    "SurfaceConvectionAlgorithm:Inside",
    "SurfaceConvectionAlgorithm:Outside",
    "ZoneAirHeatBalanceAlgorithm",
    "Site:GroundTemperature:BuildingSurface",
    "Output:Diagnostics",
    "Output:Table:SummaryReports",
    "RunPeriodControl:DaylightSavingTime",
];

/// `Class 'Name' (line N)`: how messages name an object.
pub fn object_label(class: &str, name: Option<&str>, line: usize) -> String {
    match name {
        Some(n) => format!("{class} '{n}' (line {line})"),
        None => format!("{class} (line {line})"),
    }
}

/// Reads IDF bytes: the text must be UTF-8 (plain ASCII IDFs are).
pub fn parse_idf_bytes(file: &str, bytes: &[u8]) -> Result<Vec<IdfObject>> {
    match std::str::from_utf8(bytes) {
        Ok(text) => parse_idf(file, text),
        Err(e) => {
            let at = e.valid_up_to();
            let line = 1 + bytes[..at].iter().filter(|&&b| b == b'\n').count();
            Err(Error::model(file, format!("not UTF-8 text: invalid byte 0x{:02X} at line {line} (re-save the file as UTF-8)", bytes[at])))
        }
    }
}

/// Splits IDF text into objects.
pub fn parse_idf(file: &str, text: &str) -> Result<Vec<IdfObject>> {
    let mut parser = Parser::default();
    for (i, line) in text.lines().enumerate() {
        parser.line(i + 1, strip_comment(line));
    }
    parser.finish(file)
}

/// The `Version` object's first field, e.g. `25.2`.
pub fn version(objects: &[IdfObject]) -> Option<String> {
    objects.iter().find(|o| o.is("Version")).and_then(|o| o.name()).map(str::to_string)
}

fn strip_comment(line: &str) -> &str {
    line.split_once('!').map_or(line, |(code, _)| code)
}

/// Tokenizer state across lines: the object being read and the field being accumulated.
#[derive(Default)]
struct Parser {
    objects: Vec<IdfObject>,
    /// The object being read: class, completed fields and start line.
    open: Option<IdfObject>,
    /// Text of the current token since the last separator.
    token: String,
    /// Line of the first non-blank character of the current token.
    token_line: usize,
    /// Line being read.
    current_line: usize,
}

impl Parser {
    fn line(&mut self, number: usize, code: &str) {
        self.current_line = number;
        for c in code.chars() {
            match c {
                ',' => self.end_token(false),
                ';' => self.end_token(true),
                // Newlines inside a field are never meaningful in IDF; a space keeps words apart.
                _ => self.push(number, c),
            }
        }
        if !self.token.is_empty() {
            self.token.push(' ');
        }
    }

    fn push(&mut self, line: usize, c: char) {
        if self.token.trim().is_empty() && !c.is_whitespace() {
            self.token.clear();
            self.token_line = line;
        }
        self.token.push(c);
    }

    fn end_token(&mut self, end_object: bool) {
        let token = std::mem::take(&mut self.token).trim().to_string();
        let line = if token.is_empty() { self.current_line } else { self.token_line };
        match &mut self.open {
            Some(object) => object.fields.push(token),
            None => self.open = Some(IdfObject { class: token, fields: Vec::new(), line, end_line: line }),
        }
        if end_object {
            if let Some(object) = &mut self.open {
                object.end_line = self.current_line;
            }
            self.close();
        }
    }

    fn close(&mut self) {
        if let Some(object) = self.open.take() {
            // A stray `;` (empty statement) carries nothing; EnergyPlus ignores blank input too.
            if !object.class.is_empty() || !object.fields.is_empty() {
                self.objects.push(object);
            }
        }
    }

    fn finish(self, file: &str) -> Result<Vec<IdfObject>> {
        let leftover = self.token.trim();
        if let Some(object) = &self.open {
            let name = object.name().or((object.fields.is_empty() && !leftover.is_empty()).then_some(leftover));
            let what = match name {
                Some(n) => format!("object '{}' '{n}'", object.class),
                None => format!("object '{}'", object.class),
            };
            return Err(Error::model(file, format!("{what} starting at line {} is not terminated by ';'", object.line)));
        }
        if !leftover.is_empty() {
            return Err(Error::model(file, format!("'{leftover}' at line {} is not terminated by ';'", self.token_line)));
        }
        if let Some(bad) = self.objects.iter().find(|o| o.class.is_empty()) {
            return Err(Error::model(file, format!("an object at line {} has no class name before its first ','", bad.line)));
        }
        Ok(self.objects)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SAMPLE: &str = "! header comment\n\
        Version,25.2;\n\
        \n\
        BuildingSurface:Detailed,\n\
        \x20 Wall S,        !- Name\n\
        \x20 Wall,          !- Surface Type\n\
        \x20 ,              !- Construction Name (blank)\n\
        \x20 0, 0, 3,\n\
        \x20 0, 0, 0;       !- X,Y,Z ==> Vertex 2 {m}\n\
        zone,Z1,0;  Lead Input;\n";

    #[test]
    fn splits_objects_fields_and_lines() {
        let objects = parse_idf("a.idf", SAMPLE).unwrap();
        assert_eq!(objects.len(), 4);
        assert_eq!(objects[0], IdfObject { class: "Version".into(), fields: vec!["25.2".into()], line: 2, end_line: 2 });
        let wall = &objects[1];
        assert!(wall.is("buildingsurface:detailed"));
        assert_eq!((wall.line, wall.end_line), (4, 9));
        assert_eq!(wall.fields, ["Wall S", "Wall", "", "0", "0", "3", "0", "0", "0"]);
        assert_eq!(wall.name(), Some("Wall S"));
        assert_eq!(wall.field(2), "");
        assert_eq!(wall.field(99), "");
        assert_eq!(objects[2].class, "zone");
        assert!(objects[2].is("Zone"));
        assert_eq!(objects[2].line, 10);
        assert_eq!(objects[3], IdfObject { class: "Lead Input".into(), fields: vec![], line: 10, end_line: 10 });
        assert_eq!(version(&objects).as_deref(), Some("25.2"));
        assert_eq!(wall.label(), "BuildingSurface:Detailed 'Wall S' (line 4)");
        assert_eq!(objects[0].label(), "Version (line 2)");
    }

    #[test]
    fn comments_and_whitespace_are_free() {
        let objects = parse_idf("a.idf", "  Zone ,\r\n  My  Zone ! a comment, with; separators\r\n ;").unwrap();
        assert_eq!(objects.len(), 1);
        assert_eq!(objects[0].fields, ["My  Zone"]);
        assert_eq!(objects[0].line, 1);
        assert!(parse_idf("a.idf", "! only comments\n\n;\n").unwrap().is_empty());
        assert_eq!(version(&[]), None);
    }

    #[test]
    fn unterminated_object_names_class_name_and_line() {
        let text = "Version,25.2;\n\nBuildingSurface:Detailed,\n  WALL_S,\n  Wall,\n  0,0,0\n";
        let e = parse_idf("m.idf", text).unwrap_err().to_string();
        assert_eq!(e, "m.idf: object 'BuildingSurface:Detailed' 'WALL_S' starting at line 3 is not terminated by ';'");
        let e = parse_idf("m.idf", "Version,25.2;\nZone\n").unwrap_err().to_string();
        assert!(e.contains("'Zone' at line 2 is not terminated by ';'"), "{e}");
        let e = parse_idf("m.idf", "Zone,\n  Z1\n").unwrap_err().to_string();
        assert!(e.contains("object 'Zone' 'Z1' starting at line 1"), "{e}");
    }

    #[test]
    fn missing_class_and_non_utf8_are_errors() {
        let e = parse_idf("m.idf", "Version,25.2;\n, 1, 2;\n").unwrap_err().to_string();
        assert!(e.contains("line 2") && e.contains("no class name"), "{e}");
        let e = parse_idf_bytes("m.idf", b"Version,25.2;\nZone,Caf\xe9;\n").unwrap_err().to_string();
        assert!(e.starts_with("m.idf: not UTF-8") && e.contains("line 2") && e.contains("0xE9"), "{e}");
        assert_eq!(parse_idf_bytes("m.idf", b"Zone,Z1;").unwrap().len(), 1);
    }
}
