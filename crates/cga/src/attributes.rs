//! A rule file's attributes and their annotations: what an inspector (a
//! slider for `@Range`, a drop-down for `@Enum`, ...) is built from.

use cga_value::{Value, ValueType};

use crate::diagnostics::Location;

/// An annotation as written: `@Range(min=0, max=10)` has the name `Range`
/// and the arguments `(Some("min"), Some(0))`, `(Some("max"), Some(10))`;
/// an argument that is not a constant has the value `None`.
#[derive(Clone, Debug, PartialEq)]
pub struct Annotation {
    pub name: String,
    pub args: Vec<(Option<String>, Option<Value>)>,
}

impl Annotation {
    /// The argument called `name`, else the positional one at `index`.
    pub fn arg(&self, name: &str, index: usize) -> Option<&Value> {
        self.args
            .iter()
            .find(|(n, _)| n.as_deref() == Some(name))
            .or_else(|| self.args.iter().filter(|(n, _)| n.is_none()).nth(index))
            .and_then(|(_, v)| v.as_ref())
    }

    fn number(&self, name: &str, index: usize) -> Option<f64> {
        match self.arg(name, index)? {
            Value::Float(x) => Some(*x),
            _ => None,
        }
    }

    fn text(&self, name: &str, index: usize) -> Option<String> {
        match self.arg(name, index)? {
            Value::Str(s) => Some(s.to_string()),
            _ => None,
        }
    }
}

/// `@Range`: the interval a value is meant to lie in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Range {
    pub min: f64,
    pub max: f64,
    /// The step of a slider (`stepsize`), if given.
    pub step: Option<f64>,
    /// Whether values outside are refused (`restricted`, default true).
    pub restricted: bool,
}

/// An attribute of the main rule file.
#[derive(Clone, Debug, PartialEq)]
pub struct Attribute {
    pub name: String,
    /// The type of its default value.
    pub ty: Option<ValueType>,
    /// Its default as evaluated on the default lot (`rect:20,30`, seed 0):
    /// a default that depends on the shape or draws random numbers may be
    /// another value on another lot. `None` when evaluating it failed.
    pub default: Option<Value>,
    pub annotations: Vec<Annotation>,
    /// Where it is declared.
    pub location: Option<Location>,
    /// The comment lines just above its declaration (`//`, `#`, `/* */`),
    /// without their markers.
    pub doc: Option<String>,
}

impl Attribute {
    /// The annotation called `name` (`"Range"` for `@Range`).
    pub fn annotation(&self, name: &str) -> Option<&Annotation> {
        self.annotations.iter().find(|a| a.name == name)
    }

    /// `@Range(min, max)`, `@Range(min=.., max=.., stepsize=.., restricted=..)`.
    pub fn range(&self) -> Option<Range> {
        let a = self.annotation("Range")?;
        Some(Range {
            min: a.number("min", 0)?,
            max: a.number("max", 1)?,
            step: a.number("stepsize", 2),
            restricted: !matches!(a.arg("restricted", 3), Some(Value::Bool(false))),
        })
    }

    /// The values of `@Enum(...)` (or `@Enum(values=...)`, arrays
    /// flattened), in order.
    pub fn enum_values(&self) -> Option<Vec<Value>> {
        let a = self.annotation("Enum")?;
        let mut out = Vec::new();
        for (name, v) in &a.args {
            if matches!(name.as_deref(), Some("restricted")) {
                continue;
            }
            match v {
                Some(Value::FloatArray(arr)) => {
                    out.extend(arr.data.iter().map(|&x| Value::Float(x)))
                }
                Some(Value::StrArray(arr)) => {
                    out.extend(arr.data.iter().map(|s| Value::Str(s.clone())))
                }
                Some(Value::BoolArray(arr)) => out.extend(arr.data.iter().map(|&b| Value::Bool(b))),
                Some(v) => out.push(v.clone()),
                None => {}
            }
        }
        Some(out)
    }

    /// `@Group("name", order)`: the group's name and its place among groups.
    pub fn group(&self) -> Option<(String, Option<f64>)> {
        let a = self.annotation("Group")?;
        Some((a.text("name", 0)?, a.number("order", 1)))
    }

    /// `@Order(n)`: the attribute's place in its group.
    pub fn order(&self) -> Option<f64> {
        self.annotation("Order")?.number("value", 0)
    }

    /// `@Description("...")`.
    pub fn description(&self) -> Option<String> {
        self.annotation("Description")?.text("value", 0)
    }

    /// `@Hidden`: not shown in an inspector.
    pub fn is_hidden(&self) -> bool {
        self.annotation("Hidden").is_some()
    }

    /// `@Color`: a colour string (`"#rrggbb"`).
    pub fn is_color(&self) -> bool {
        self.annotation("Color").is_some()
    }

    /// `@File(...)`: a file of the workspace; the file extensions it
    /// accepts (empty: any).
    pub fn file_extensions(&self) -> Option<Vec<String>> {
        let a = self.annotation("File")?;
        Some(
            a.args
                .iter()
                .filter_map(|(_, v)| match v {
                    Some(Value::Str(s)) => Some(s.to_string()),
                    Some(Value::StrArray(arr)) => Some(
                        arr.data
                            .iter()
                            .map(|s| s.to_string())
                            .collect::<Vec<_>>()
                            .join(";"),
                    ),
                    _ => None,
                })
                .flat_map(|s| {
                    s.split([';', ',', ' '])
                        .filter(|e| !e.is_empty())
                        .map(|e| e.trim_start_matches("*.").to_string())
                        .collect::<Vec<_>>()
                })
                .collect(),
        )
    }
}
