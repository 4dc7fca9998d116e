//! The serde seeds that read a path: the registry is passed down explicitly (bevy's
//! `DeserializeWithRegistry` pattern), to nested operator lists too, through [`Reader`].

use std::cell::Cell;
use std::fmt;
use std::sync::Arc;

use cov_core::spec::FieldName;
use cov_core::{Chain, Operator, OperatorReader, echo, layout_set};
use serde::de::{
    self, DeserializeSeed, Deserializer, EnumAccess, MapAccess, SeqAccess, VariantAccess, Visitor,
};

use crate::path::{Path, axes_string};
use crate::registry::{Entry, Registry};
use crate::scan::Element;
use crate::source::Source;

/// The parse context: the registry, what the scan saw of each operator element, and
/// the rules that span elements (one sensor, at the end of the top-level list).
pub(crate) struct Reader<'r> {
    pub(crate) registry: &'r Registry,
    elements: Vec<Element>,
    next: Cell<usize>,
    terminal: Cell<Option<&'static str>>,
}

impl<'r> Reader<'r> {
    pub(crate) fn new(registry: &'r Registry, elements: Vec<Element>) -> Self {
        Reader {
            registry,
            elements,
            next: Cell::new(0),
            terminal: Cell::new(None),
        }
    }
}

impl OperatorReader for Reader<'_> {
    fn read_operators<'de, D: Deserializer<'de>>(&self, d: D) -> Result<Chain, D::Error> {
        let ops = OpsSeed {
            reader: self,
            layout: None,
            top: false,
        }
        .deserialize(d)?;
        let mut chain = Chain::new();
        for op in ops {
            chain.push_shared(op);
        }
        Ok(chain)
    }
}

/// First pass: reads `layout` only.
pub(crate) struct LayoutProbe;

pub(crate) const FIELDS: &[&str] = &["layout", "source", "operators"];

impl<'de> DeserializeSeed<'de> for LayoutProbe {
    type Value = Option<usize>;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Option<usize>, D::Error> {
        d.deserialize_struct("Path", FIELDS, self)
    }
}

impl<'de> Visitor<'de> for LayoutProbe {
    type Value = Option<usize>;
    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a path")
    }
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Option<usize>, A::Error> {
        let mut layout = None;
        while let Some(key) = map.next_key_seed(FieldName)? {
            if key == "layout" {
                layout = Some(map.next_value::<usize>()?);
            } else {
                map.next_value::<de::IgnoredAny>()?;
            }
        }
        Ok(layout.filter(|n| (2..=5).contains(n)))
    }
}

/// Second pass: the path, checked against the declared layout as it is read.
pub(crate) struct PathSeed<'a, 'r> {
    pub(crate) reader: &'a Reader<'r>,
    pub(crate) declared: Option<usize>,
}

impl<'de> DeserializeSeed<'de> for PathSeed<'_, '_> {
    type Value = Path;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Path, D::Error> {
        d.deserialize_struct("Path", FIELDS, self)
    }
}

impl<'de> Visitor<'de> for PathSeed<'_, '_> {
    type Value = Path;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a path: Path(layout: N (optional), source: ..., operators: [...])")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Path, A::Error> {
        let mut layout: Option<usize> = None;
        let mut source: Option<Source> = None;
        let mut operators: Option<Vec<Arc<dyn Operator>>> = None;
        while let Some(key) = map.next_key_seed(FieldName)? {
            match key.as_str() {
                "layout" => {
                    if layout.is_some() {
                        return Err(de::Error::duplicate_field("layout"));
                    }
                    // Read signed, so that a negative layout gets the same words.
                    let n: i64 = map.next_value()?;
                    if !(2..=5).contains(&n) {
                        return Err(de::Error::custom(format!(
                            "layout must be 2 (x,u), 3 (x,u,t), 4 (x,y,u,v) or 5 (x,y,u,v,t), got {n}"
                        )));
                    }
                    layout = Some(n as usize);
                }
                "source" => {
                    if source.is_some() {
                        return Err(de::Error::duplicate_field("source"));
                    }
                    let s: Source = map.next_value()?;
                    s.check(layout.or(self.declared)).map_err(de::Error::custom)?;
                    source = Some(s);
                }
                "operators" => {
                    if operators.is_some() {
                        return Err(de::Error::duplicate_field("operators"));
                    }
                    operators = Some(map.next_value_seed(OpsSeed {
                        reader: self.reader,
                        layout: layout.or(self.declared),
                        top: true,
                    })?);
                }
                other => return Err(de::Error::unknown_field(&echo(other), FIELDS)),
            }
        }
        let source = source.ok_or_else(|| de::Error::missing_field("source"))?;
        let operators = operators.ok_or_else(|| de::Error::missing_field("operators"))?;
        if operators.is_empty() {
            return Err(de::Error::custom("the path has no operators (`operators: []`)"));
        }
        let mut chain = Chain::new();
        for op in operators {
            chain.push_shared(op);
        }
        Ok(Path {
            file: "<string>".into(),
            layout,
            source,
            operators: chain,
            positions: Vec::new(),
        })
    }
}

/// An operator list; `top` for the path's own.
struct OpsSeed<'a, 'r> {
    reader: &'a Reader<'r>,
    layout: Option<usize>,
    top: bool,
}

impl<'de> DeserializeSeed<'de> for OpsSeed<'_, '_> {
    type Value = Vec<Arc<dyn Operator>>;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
        d.deserialize_seq(self)
    }
}

impl<'de> Visitor<'de> for OpsSeed<'_, '_> {
    type Value = Vec<Arc<dyn Operator>>;
    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a list of operators, e.g. [Travel(distance: 1.0)]")
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
        let mut out = Vec::new();
        while let Some(op) = seq.next_element_seed(OpSeed {
            reader: self.reader,
            layout: self.layout,
            top: self.top,
        })? {
            out.push(op);
        }
        Ok(out)
    }
}

struct OpSeed<'a, 'r> {
    reader: &'a Reader<'r>,
    layout: Option<usize>,
    top: bool,
}

impl<'de> DeserializeSeed<'de> for OpSeed<'_, '_> {
    type Value = Arc<dyn Operator>;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
        d.deserialize_enum("Operator", &[], self)
    }
}

impl<'de> Visitor<'de> for OpSeed<'_, '_> {
    type Value = Arc<dyn Operator>;
    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("an operator, e.g. Travel(distance: 1.0)")
    }
    fn visit_enum<A: EnumAccess<'de>>(self, data: A) -> Result<Self::Value, A::Error> {
        let reader = self.reader;
        let ordinal = reader.next.get();
        reader.next.set(ordinal + 1);
        let bare = reader.elements.get(ordinal).map(|e| e.bare);
        let (name, variant) = data.variant_seed(FieldName)?;
        let Some(entry) = reader.registry.get(&name) else {
            let left_out = reader.registry.left_out();
            let absent = (!left_out.is_empty()).then(|| {
                let list: Vec<String> = left_out.iter().map(|f| format!("`{f}`")).collect();
                format!("this build leaves out covtrace's features {}", list.join(", "))
            });
            let hint = match (reader.registry.closest(&name), absent) {
                (Some(near), None) => format!(" (did you mean `{near}`?)"),
                (Some(near), Some(absent)) => format!(" (did you mean `{near}`? {absent})"),
                // An operator of the user's own is read by a binary that registers it.
                (None, absent) => format!(
                    " ({}an operator of your own needs a binary that registers it: `cov_cli::run_with`, docs/paths.md)",
                    absent.map(|a| format!("{a}; ")).unwrap_or_default()
                ),
            };
            return Err(de::Error::custom(format!(
                "unknown operator `{}`{hint}; known operators: {}",
                echo(&name),
                reader.registry.names()
            )));
        };
        if let Some(sensor) = reader.terminal.get()
            && self.top
        {
            return Err(de::Error::custom(format!(
                "`{name}` after `{sensor}`: a `{sensor}` ends the path, so nothing may follow it"
            )));
        }
        let op = if bare == Some(true) {
            variant.unit_variant()?;
            match (entry.defaults)() {
                Some(Ok(op)) => op,
                Some(Err(e)) => return Err(de::Error::custom(e)),
                None => return Err(de::Error::custom(needs_parameters(entry))),
            }
        } else {
            variant.newtype_variant_seed(EntrySeed { entry, reader })?
        };
        if op.is_terminal() {
            if !self.top {
                return Err(de::Error::custom(format!(
                    "`{name}` inside another operator's list: a `{name}` ends the path and stands only in the path's own `operators` list"
                )));
            }
            reader.terminal.set(Some(entry.name));
        }
        if let Some(n) = self.layout {
            let have = layout_set(n);
            if let Some(axis) = op.requires().iter().find(|a| !have.contains(*a)) {
                return Err(de::Error::custom(format!(
                    "operator `{name}` needs axis `{axis}`, which layout {n} ({}) does not have",
                    axes_string(n)
                )));
            }
        }
        Ok(op)
    }
}

fn needs_parameters(entry: &Entry) -> String {
    let required: Vec<&str> = entry
        .params
        .iter()
        .filter(|p| p.default.is_none())
        .map(|p| p.name)
        .collect();
    format!(
        "`{}` needs parameters: write `{}({}: …)`",
        entry.name,
        entry.name,
        required.join(": …, ")
    )
}

struct EntrySeed<'e, 'a, 'r> {
    entry: &'e Entry,
    reader: &'a Reader<'r>,
}

impl<'de> DeserializeSeed<'de> for EntrySeed<'_, '_, '_> {
    type Value = Arc<dyn Operator>;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
        let mut erased = <dyn erased_serde::Deserializer>::erase(d);
        let name = self.entry.name;
        (self.entry.build)(&mut erased, self.reader).map_err(|e| {
            let msg = e.to_string();
            if msg.starts_with(&format!("{name}: ")) {
                de::Error::custom(msg)
            } else {
                de::Error::custom(format!("{name}: {msg}"))
            }
        })
    }
}
