//! Receivers chosen by attribute: the `where` rules of city models (`function=residential`,
//! `storeysAboveGround>=3`, `slope<30`), which every command applies alike through the load
//! ([`super::LoadOptions::attribute_rules`]) and a district's first pass through
//! [`super::CityReceivers`].
//!
//! Owns:
//! - a rule's form `KEY OP VALUE`, OP one of `=`, `!=`, `<`, `<=`, `>`, `>=`; the key is an
//!   attribute's name as written (case-sensitive, as JSON's), the value the rest of the text;
//! - where a key is looked up: the surface's semantic surface's own attributes, then its
//!   CityObject's `attributes`, then its parents' ([`SurfaceAttributes`]);
//! - how values compare: a number attribute against a number value compares as numbers (`3`
//!   matches `3.0`); `=` and `!=` otherwise compare text as a case-insensitive glob (`res*`; a
//!   boolean as `true`/`false`); `<`, `<=`, `>`, `>=` compare numbers only (a string attribute
//!   counts when it reads wholly as a number, as some exports write numbers); an array attribute
//!   meets `=` and the orders when one of its items does. A surface without the key (or with it
//!   null) meets no rule, `!=` included: `!=` is "has the key, with another value";
//! - several rules: a receiver meets them all;
//! - the counts that name, when no receiver is left, the rule that left none ([`WhereRules`]).

use serde_json::Value;

use super::cityjson::SurfaceAttributes;
use crate::error::{Error, NoReceivers, Result};

/// How a rule compares.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Op {
    Eq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
}

/// The operators in the order they are tried at a position (two characters before one).
const OPS: [(&str, Op); 6] = [("!=", Op::Ne), ("<=", Op::Le), (">=", Op::Ge), ("=", Op::Eq), ("<", Op::Lt), (">", Op::Gt)];

/// One rule, parsed.
#[derive(Debug, Clone)]
pub struct AttributeRule {
    /// As given.
    text: String,
    key: String,
    op: Op,
    /// The value as text, and as a number when it reads as one.
    value: String,
    number: Option<f64>,
    glob: globset::GlobMatcher,
}

impl AttributeRule {
    /// Parses `KEY OP VALUE`; refuses a rule without a key or an operator, an order against what
    /// is not a number, and a value that is no glob.
    pub fn parse(text: &str) -> Result<Self> {
        let bad = |why: String| Error::argument("where", format!("'{text}': {why}"));
        let at = text.find(['=', '!', '<', '>']).ok_or_else(|| bad("no operator (=, !=, <, <=, >, >=): write KEY=VALUE".into()))?;
        let (op_text, op) =
            OPS.iter().find(|(o, _)| text[at..].starts_with(o)).ok_or_else(|| bad(format!("'{}' is no operator", &text[at..at + 1])))?;
        let key = text[..at].trim();
        if key.is_empty() {
            return Err(bad("no attribute name before the operator".into()));
        }
        let value = text[at + op_text.len()..].trim().to_string();
        let number = value.parse::<f64>().ok().filter(|n| n.is_finite());
        if number.is_none() && !matches!(op, Op::Eq | Op::Ne) {
            return Err(bad(format!("{op_text} compares numbers, and '{value}' is not one")));
        }
        let glob = globset::GlobBuilder::new(&value).case_insensitive(true).build().map_err(|e| bad(e.to_string()))?.compile_matcher();
        Ok(Self { text: text.to_string(), key: key.to_string(), op: *op, value, number, glob })
    }

    /// The attribute it asks for.
    pub fn key(&self) -> &str {
        &self.key
    }

    /// Whether a surface with `attributes` meets it.
    pub fn holds(&self, attributes: &SurfaceAttributes) -> bool {
        match attributes.get(&self.key) {
            None | Some(Value::Null) => false,
            Some(v) if self.op == Op::Ne => !self.equal(v),
            Some(Value::Array(items)) => items.iter().any(|i| self.holds_for(i)),
            Some(v) => self.holds_for(v),
        }
    }

    /// `=` or an order against one value (not an array).
    fn holds_for(&self, v: &Value) -> bool {
        if matches!(self.op, Op::Eq | Op::Ne) {
            return self.equal(v);
        }
        let (Some(a), Some(b)) = (number_of(v), self.number) else { return false };
        match self.op {
            Op::Lt => a < b,
            Op::Le => a <= b,
            Op::Gt => a > b,
            Op::Ge => a >= b,
            Op::Eq | Op::Ne => false,
        }
    }

    /// Whether `v` equals the value: as numbers when both are, else as text (a glob).
    fn equal(&self, v: &Value) -> bool {
        match (v, self.number) {
            (Value::Number(n), Some(b)) => n.as_f64() == Some(b),
            (Value::String(s), _) => self.glob.is_match(s),
            (Value::Array(items), _) => items.iter().any(|i| self.equal(i)),
            (Value::Null, _) => false,
            (other, _) => {
                // A boolean (or an object) as its JSON text: `true`, `false`.
                let text = other.to_string();
                self.glob.is_match(&text) || text == self.value
            }
        }
    }
}

/// A number attribute, or a string that reads wholly as one.
fn number_of(v: &Value) -> Option<f64> {
    match v {
        Value::Number(n) => n.as_f64(),
        Value::String(s) => s.trim().parse::<f64>().ok().filter(|n| n.is_finite()),
        _ => None,
    }
}

/// The `where` rules of one load, and what they saw: for each rule, how many of the surfaces
/// put to them had its key and how many met it, so that a load left without receivers names the
/// rule (and its attribute) that left none.
#[derive(Debug, Clone, Default)]
pub struct WhereRules {
    rules: Vec<AttributeRule>,
    /// Surfaces put to the rules.
    seen: usize,
    /// Per rule: surfaces that had its key, and that met it.
    keyed: Vec<usize>,
    met: Vec<usize>,
    /// Surfaces that met every rule.
    admitted: usize,
}

impl WhereRules {
    /// The rules of `texts` (none: every surface is admitted).
    pub fn new(texts: &[String]) -> Result<Self> {
        let rules = texts.iter().map(|t| AttributeRule::parse(t)).collect::<Result<Vec<_>>>()?;
        let n = rules.len();
        Ok(Self { rules, keyed: vec![0; n], met: vec![0; n], ..Default::default() })
    }

    /// Whether there are rules.
    pub fn is_empty(&self) -> bool {
        self.rules.is_empty()
    }

    /// Whether a surface with `attributes` (none: not a city surface) meets every rule; counted.
    pub fn admit(&mut self, attributes: Option<&SurfaceAttributes>) -> bool {
        if self.rules.is_empty() {
            return true;
        }
        self.seen += 1;
        let empty = SurfaceAttributes::default();
        let attributes = attributes.unwrap_or(&empty);
        let mut all = true;
        for (i, rule) in self.rules.iter().enumerate() {
            self.keyed[i] += attributes.has(rule.key()) as usize;
            let holds = rule.holds(attributes);
            self.met[i] += holds as usize;
            all &= holds;
        }
        self.admitted += all as usize;
        all
    }

    /// Why no surface was admitted, when surfaces were put to the rules and none met them all:
    /// the first rule none met (its attribute absent from all, or no value meeting it), else the
    /// rules together. `None` when a surface was admitted or none was put to them.
    pub fn refusal(&self) -> Option<NoReceivers> {
        if self.rules.is_empty() || self.seen == 0 || self.admitted > 0 {
            return None;
        }
        let seen = self.seen;
        let (rule, reason) = match self.rules.iter().enumerate().find(|(i, _)| self.met[*i] == 0) {
            Some((i, rule)) if self.keyed[i] == 0 => {
                (rule.text.clone(), format!("no surface of the {seen} chosen has the attribute '{}'", rule.key()))
            }
            Some((i, rule)) => (
                rule.text.clone(),
                format!("of the {seen} surfaces chosen, {} have the attribute '{}', and none meets the rule", self.keyed[i], rule.key()),
            ),
            None => {
                let texts: Vec<&str> = self.rules.iter().map(|r| r.text.as_str()).collect();
                (texts.join(", "), format!("of the {seen} surfaces chosen, none meets these rules together"))
            }
        };
        Some(NoReceivers::Where { rule, reason })
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn attrs(json: &str) -> SurfaceAttributes {
        SurfaceAttributes::of(vec![std::sync::Arc::new(serde_json::from_str(json).unwrap())])
    }

    fn holds(rule: &str, json: &str) -> bool {
        AttributeRule::parse(rule).unwrap().holds(&attrs(json))
    }

    #[test]
    fn rules_compare_numbers_as_numbers_and_text_as_globs() {
        let a = r#"{"function": "Residential", "storeys": 3, "height": 9.5, "code": "1000", "roofs": ["flat", "gabled"], "listed": false, "gone": null}"#;
        for (rule, want) in [
            ("function=residential", true),
            ("function = res*", true),
            ("function!=residential", false),
            ("function!=office", true),
            ("storeys=3.0", true),
            ("storeys=3", true),
            ("storeys>=3", true),
            ("storeys>3", false),
            ("storeys<4", true),
            ("height<=9.5", true),
            ("height>9.49", true),
            ("height=9.50", true),
            // A string that reads as a number orders as one; equality stays text.
            ("code>999", true),
            ("code=1000", true),
            ("code=1000.0", false),
            ("roofs=gabled", true),
            ("roofs!=gabled", false),
            ("listed=false", true),
            // Absent or null: no rule is met, != included.
            ("gone=x", false),
            ("gone!=x", false),
            ("missing!=x", false),
            ("missing<1", false),
            // A number attribute against text.
            ("storeys=three", false),
            ("storeys!=three", true),
        ] {
            assert_eq!(holds(rule, a), want, "{rule}");
        }
    }

    #[test]
    fn malformed_rules_are_refused_naming_them() {
        for (rule, why) in [
            ("function", "no operator"),
            ("=residential", "no attribute name"),
            ("storeys<three", "< compares numbers, and 'three' is not one"),
            ("function!residential", "'!' is no operator"),
        ] {
            let e = AttributeRule::parse(rule).unwrap_err().to_string();
            assert!(e.starts_with(&format!("invalid where: '{rule}': ")) && e.contains(why), "{rule}: {e}");
        }
    }

    #[test]
    fn the_refusal_names_the_rule_that_left_no_surface() {
        let mut rules = WhereRules::new(&["function=office".into(), "storeys>1".into()]).unwrap();
        assert!(rules.refusal().is_none(), "nothing seen yet");
        assert!(!rules.admit(Some(&attrs(r#"{"function": "residential", "storeys": 3}"#))));
        assert!(!rules.admit(None));
        let why = Error::NoReceivers(rules.refusal().unwrap()).to_string();
        assert_eq!(
            why,
            "no receiving surface: where function=office: of the 2 surfaces chosen, 1 have the attribute 'function', and none meets the rule"
        );
        let mut absent = WhereRules::new(&["usage=x".into()]).unwrap();
        absent.admit(Some(&attrs(r#"{"function": "x"}"#)));
        let why = Error::NoReceivers(absent.refusal().unwrap()).to_string();
        assert!(why.ends_with("where usage=x: no surface of the 1 chosen has the attribute 'usage'"), "{why}");
        let mut ok = WhereRules::new(&["function=x".into()]).unwrap();
        assert!(ok.admit(Some(&attrs(r#"{"function": "x"}"#))));
        assert!(ok.refusal().is_none());
    }
}
