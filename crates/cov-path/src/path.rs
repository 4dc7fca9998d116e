//! A parsed light path: parsing, layout inference.

use cov_core::{AxisSet, Chain, Operator, layout_axes, layout_set};
use ron::extensions::Extensions;

use crate::de::{LayoutProbe, PathSeed, Reader};
use crate::error::PathError;
use crate::registry::Registry;
use crate::source::Source;

/// A parsed light path.
#[derive(Clone, Debug)]
pub struct Path {
    /// The file it was read from (`<string>` for text).
    pub file: String,
    /// The layout the file fixes, if any.
    pub layout: Option<usize>,
    /// The initial covariance.
    pub source: Source,
    /// The operators, in order.
    pub operators: Chain,
    /// Line and column of each operator in the text (empty when not known).
    pub positions: Vec<(usize, usize)>,
}

/// The options every path file is read with: `Some` may be left out, and a newtype
/// variant's struct may be written inline (`Travel(distance: 1)`).
pub fn ron_options() -> ron::Options {
    ron::Options::default()
        .with_default_extension(Extensions::IMPLICIT_SOME | Extensions::UNWRAP_VARIANT_NEWTYPES)
}

/// A parser error in the path author's terms, at the place it concerns: an operator's
/// parameter out of range at that parameter (ron reports it at the operator's end); a
/// value of the wrong type named by its parameter, with the domain `registry` declares for
/// it; a number where a name belongs, a decimal where a whole number belongs and the
/// parser's recursion limit in words; everything else as ron says it.
fn explain(
    text: &str,
    line: usize,
    col: usize,
    code: &ron::Error,
    registry: &Registry,
) -> (usize, usize, String) {
    let msg = code.to_string();
    // A custom message keeps the operators' names in front (`Travel: …`, and
    // `Moving: Travel: …` inside a nested list).
    let mut ops: Vec<&str> = Vec::new();
    let mut rest = msg.as_str();
    while let Some((op, tail)) = rest.split_once(": ")
        && !op.is_empty()
        && !op.contains(' ')
    {
        ops.push(op);
        rest = tail;
    }
    let prefix: String = ops.iter().map(|op| format!("{op}: ")).collect();
    let rest = rest.to_string();
    if let Some(((l, c), words)) = crate::scan::odd_space_before(text, line, col) {
        return (l, c, words);
    }
    if let Some(((l, c), words)) = crate::scan::token_error(text, line, col, &msg) {
        return (l, c, words);
    }
    // `0x10` where a decimal number belongs: ron reads the `0` and stops at the `x`.
    if let Some((name, (l, c), value)) = crate::scan::field_at(text, line, col)
        && let Some(words) = not_decimal(&value)
    {
        return (
            l,
            c,
            format!("{prefix}parameter `{name}` = {}: {words}", cov_core::echo(&value)),
        );
    }
    if let Some(found) = wrong_type(
        text,
        (line, col),
        &prefix,
        &rest,
        ops.last().and_then(|op| registry.get(op)),
    ) {
        return found;
    }
    // A value of the wrong type inside a parameter's list (`hessian: [40.0, "a", 15.0]`).
    if let Some(((name, _, _), index, element)) = crate::scan::element_at(text, line, col)
        && let Some(what) = expected_value(&rest, &element)
        && !what.is_empty()
    {
        return (
            line,
            col,
            format!(
                "{prefix}parameter `{name}`: value {} = {}: expected {what}",
                index + 1,
                cov_core::echo(&element)
            ),
        );
    }
    // An operator's parameters in the path author's words rather than the parser's; a
    // name outside a parameter's choices (an enum's variant) says which parameter.
    if !prefix.is_empty()
        && let Some(words) = parameter_words(&rest)
    {
        if rest.starts_with("Unexpected enum variant")
            && let Some((name, _, _)) = crate::scan::field_at(text, line, col)
        {
            return (line, col, format!("{prefix}parameter `{name}`: {words}"));
        }
        return (line, col, format!("{prefix}{words}"));
    }
    if let Some(tail) = rest.strip_prefix("Found invalid std identifier \"") {
        let found = tail.split('"').next().unwrap_or("");
        return (
            line,
            col,
            format!(
                "{prefix}expected a name here (a parameter, an operator or an axis such as `x`), found `{}`",
                cov_core::echo(found)
            ),
        );
    }
    if rest.starts_with("Exceeded recursion limit") {
        return (
            line,
            col,
            format!(
                "{prefix}nested too deeply for the parser (operator lists may nest at most {} deep)",
                crate::scan::MAX_NESTING
            ),
        );
    }
    if decimal_for_whole(&rest, text, line, col) {
        const WORDS: &str = "expected a whole number, found a decimal number";
        let message = match whole_number_at(text, line, col) {
            Some((name, None, value)) => {
                format!("{prefix}parameter `{name}` = {}: {WORDS}", cov_core::echo(&value))
            }
            Some((name, Some(k), value)) => format!(
                "{prefix}parameter `{name}`: value {} = {}: {WORDS}",
                k + 1,
                cov_core::echo(&value)
            ),
            None => format!("{prefix}expected a whole number here, found a decimal number"),
        };
        return (line, col, message);
    }
    // `parameter `name`` (a source's `std `name``): point at the parameter where it is
    // written.
    if let Some(tail) = rest
        .split("parameter `")
        .nth(1)
        .or_else(|| rest.strip_prefix("Gaussian source: std `"))
        && let Some(name) = tail.split('`').next()
        && let Some((l, c)) = crate::scan::field_position(text, line, col, name)
    {
        // A number a float cannot hold, which the check reports as `inf` or 0.
        if let Some((found, _, value)) = crate::scan::field_at(text, l, c + name.chars().count() + 1)
            && found == name
            && let Some(words) = beyond_float(&value)
        {
            let value = cov_core::echo(&value);
            return (l, c, format!("{prefix}parameter `{name}` = {value}: {words}"));
        }
        return (l, c, msg);
    }
    (line, col, msg)
}

/// ron's message that a value has the wrong type, said of the parameter it was given to
/// (`entry`: the operator's, for the parameter's declared domain), at the parameter's
/// name, after `prefix` (the operators' names). `None` for any other message, or when the parameter cannot be found.
fn wrong_type(
    text: &str,
    (line, col): (usize, usize),
    prefix: &str,
    rest: &str,
    entry: Option<&crate::registry::Entry>,
) -> Option<(usize, usize, String)> {
    let (name, (l, c), value) = crate::scan::field_at(text, line, col)?;
    // Inside an operator, a name in quotes where a name belongs and a value where a list
    // belongs (ron's "Expected identifier" also means a syntax error, as `,,`, hence the
    // quote; outside an operator, the path's own fields are no parameters).
    let what = match rest {
        "Expected identifier" if !prefix.is_empty() && value.starts_with('"') => "a name, without quotes",
        "Expected opening `[`" if !prefix.is_empty() => "a list in brackets, `[…]`",
        _ => expected_value(rest, &value)?,
    };
    let domain = entry
        .and_then(|e| e.params.iter().find(|p| p.name == name))
        .map(|p| p.domain)
        .filter(|d| !d.is_empty() && *d != "finite");
    let value = cov_core::echo(&value);
    let message = match (what, domain) {
        ("", Some(d)) => format!("parameter `{name}` = {value} is out of range: must be {d}"),
        ("", None) => format!("parameter `{name}` = {value} is out of range for its type"),
        (w, Some(d)) => format!("parameter `{name}` = {value}: expected {w}, {d}"),
        (w, None) => format!("parameter `{name}` = {value}: expected {w}"),
    };
    Some((l, c, format!("{prefix}{message}")))
}

/// Whether ron's message `ron_message` at `(line, col)` of `text` (1-based, as ron
/// reports it) is a decimal number where a whole number belongs: ron reads the digits
/// before the `.` or the exponent's `e` as the whole number and then stops there, saying
/// it expected a comma (or a tuple's closing parenthesis) at the `.` (`128.0`), or, at the
/// number's start, that `e` is no digit (`9e1`).
pub fn decimal_for_whole(ron_message: &str, text: &str, line: usize, col: usize) -> bool {
    let chars = row(text, line);
    let at = col.saturating_sub(1);
    // After the last value of a tuple ron expects its closing parenthesis instead.
    if ron_message == "Expected comma" || ron_message.starts_with("Expected closing `)`") {
        let digit_before = at > 0 && chars.get(at - 1).is_some_and(|c| c.is_ascii_digit());
        return digit_before && matches!(chars.get(at), Some('.' | 'e' | 'E'));
    }
    if ron_message.starts_with("Invalid digit ") {
        let number: String = chars
            .iter()
            .skip(at)
            .take_while(|c| c.is_ascii_alphanumeric() || matches!(c, '.' | '+' | '-' | '_'))
            .collect();
        return number.contains(['.', 'e', 'E']) && number.replace('_', "").parse::<f64>().is_ok();
    }
    false
}

/// The column (1-based, as ron counts) where the number that `(line, col)` of `text`
/// points into or just after its sign begins: ron reports a decimal where a whole number
/// belongs at its `.`, and a negative whole number out of range after its `-`.
pub fn number_start(text: &str, line: usize, col: usize) -> usize {
    let row = row(text, line);
    let mut c = col.clamp(1, row.len().max(1));
    while c > 1
        && row
            .get(c - 2)
            .is_some_and(|ch| ch.is_ascii_digit() || matches!(ch, '_' | '.' | '+' | '-'))
    {
        c -= 1;
    }
    c
}

/// Where a decimal number that ron refused as a whole number ([`decimal_for_whole`], at
/// `(line, col)` of `text`) is written: the field's name, the number's index (from 0) in
/// the tuple or list that is the field's value (`None`: the field's value itself), and
/// the value as written.
pub fn whole_number_at(text: &str, line: usize, col: usize) -> Option<(String, Option<usize>, String)> {
    let start = number_start(text, line, col);
    if let Some((name, _, value)) = crate::scan::field_at(text, line, start) {
        return Some((name, None, value));
    }
    let ((name, _, _), index, element) = crate::scan::element_at(text, line, start)?;
    Some((name, Some(index), element))
}

/// Row `line` (from 1) of `text` as characters; a leading byte-order mark is not counted,
/// as ron does not count it in its columns.
fn row(text: &str, line: usize) -> Vec<char> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    text.lines()
        .nth(line.saturating_sub(1))
        .unwrap_or("")
        .chars()
        .collect()
}

/// What is wrong with a number written in another base (`0x10`, `0b1`, `0o7`, signed or
/// not) where covtrace reads decimals: ron reads the leading `0` of it as a decimal number
/// and stops at the letter. `None` for anything else.
pub fn not_decimal(written: &str) -> Option<&'static str> {
    let digits = written.trim_start_matches(['-', '+']);
    let base = match digits.get(..2)? {
        "0x" | "0X" => "hexadecimal",
        "0b" | "0B" => "binary",
        "0o" | "0O" => "octal",
        _ => return None,
    };
    Some(match base {
        "hexadecimal" => "a hexadecimal number; write it in decimal (`0x10` is 16.0)",
        "binary" => "a binary number; write it in decimal (`0b101` is 5.0)",
        _ => "an octal number; write it in decimal (`0o17` is 15.0)",
    })
}

/// What is wrong with `written`, a number as a file writes it, that a float cannot hold:
/// too large (`1e400`, read as infinite) or, not zero, too small (`1e-400`, read as 0). A
/// check of the value read would say "got inf" or "got 0" of a value the user did not
/// write. `None` for any other.
pub fn beyond_float(written: &str) -> Option<&'static str> {
    let w = written.trim();
    let v = w.parse::<f64>().ok()?;
    let mantissa = w.split(['e', 'E']).next().unwrap_or("");
    if v.is_infinite() && !w.to_ascii_lowercase().contains("inf") {
        Some("beyond the largest number a float holds (about 1.8e308)")
    } else if v == 0.0 && mantissa.chars().any(|c| matches!(c, '1'..='9')) {
        Some("below the smallest number a float holds (about 4.9e-324), read as 0")
    } else {
        None
    }
}

/// What ron's message that a value has the wrong type says was expected, in a file
/// author's words (`Expected float`: "a number"); "" for a whole number outside its
/// type's range (`Integer is out of bounds`); `None` for any other message. Paths and
/// scenes name the field with [`crate::field_at`], whose value as written is `written`: a
/// `nan` where a number was expected is said to be no finite number.
pub fn expected_value(ron_message: &str, written: &str) -> Option<&'static str> {
    let nan = written.trim_start_matches(['-', '+']).eq_ignore_ascii_case("nan");
    Some(match ron_message {
        "Expected float" if nan => "a finite number, not NaN",
        "Expected float" => "a number",
        "Expected integer" => "a whole number",
        "Integer is out of bounds" => "",
        "Expected boolean" => "`true` or `false`",
        "Expected string" => "a string in double quotes",
        _ => return None,
    })
}

/// ron's messages about a struct's fields, said of an operator's parameters: missing,
/// unknown (with the ones it takes) and repeated. `None` for any other message.
fn parameter_words(rest: &str) -> Option<String> {
    let name_after = |prefix: &str| rest.strip_prefix(prefix).and_then(|t| t.split_once('`'));
    // A name outside a list of choices (an axis `w`, a lobe `Phng`).
    if let Some((name, after)) = name_after("Unexpected enum variant named `")
        && let Some(choices) = after
            .strip_prefix(", expected one of ")
            .or_else(|| after.strip_prefix(", expected "))
            .and_then(|c| c.strip_suffix(" instead"))
    {
        // serde says "either `a` or `b`" of two choices.
        let choices = choices.strip_prefix("either ").unwrap_or(choices);
        return Some(format!("unknown name `{name}`: expected one of {choices}"));
    }
    if let Some((name, _)) = name_after("Unexpected missing field named `") {
        return Some(format!("missing parameter `{name}`"));
    }
    if let Some((name, _)) = name_after("Unexpected duplicate field named `") {
        return Some(format!("parameter `{name}` is given twice"));
    }
    let (name, after) = name_after("Unexpected field named `")?;
    if after.contains("there are no fields") {
        return Some(format!("unknown parameter `{name}`: this operator takes none"));
    }
    let expected = after.strip_suffix(" instead")?;
    if let Some(list) = expected.strip_prefix(", expected one of ") {
        return Some(format!("unknown parameter `{name}`; the parameters are {list}"));
    }
    let one = expected.strip_prefix(", expected ")?;
    Some(format!("unknown parameter `{name}`; the parameter is {one}"))
}

impl Path {
    /// Parses a path from RON text with the operators of `registry`.
    ///
    /// # Errors
    /// [`PathError::Parse`] with the line and column of the problem.
    pub fn parse(text: &str, registry: &Registry) -> Result<Path, PathError> {
        let elements = crate::scan::operator_elements(text);
        if let Some(e) = elements.iter().find(|e| e.depth > crate::scan::MAX_NESTING) {
            return Err(PathError::Parse {
                file: "<string>".into(),
                line: e.line,
                col: e.col,
                message: format!(
                    "operator lists nest {} deep here; at most {} (a `Moving` inside a `Moving` …)",
                    e.depth,
                    crate::scan::MAX_NESTING
                ),
            });
        }
        if let Some(e) = elements.get(crate::scan::MAX_OPERATORS) {
            return Err(PathError::Parse {
                file: "<string>".into(),
                line: e.line,
                col: e.col,
                message: format!(
                    "the path holds {} operators; at most {} (this is the first one past it)",
                    elements.len(),
                    crate::scan::MAX_OPERATORS
                ),
            });
        }
        // First pass: the declared layout, wherever it stands in the file, so that the
        // second pass can check every operator against it where it is written.
        let declared = ron_options().from_str_seed(text, LayoutProbe).ok().flatten();
        let reader = Reader::new(registry, elements);
        let mut path = ron_options()
            .from_str_seed(
                text,
                PathSeed {
                    reader: &reader,
                    declared,
                },
            )
            .map_err(|e| {
                let (line, col, message) =
                    explain(text, e.span.start.line, e.span.start.col, &e.code, registry);
                PathError::Parse {
                    file: "<string>".into(),
                    line,
                    col,
                    message,
                }
            })?;
        let positions = crate::scan::operator_positions(text);
        if positions.len() == path.operators.len() {
            path.positions = positions;
        }
        Ok(path)
    }

    /// Parses text and names it `file` in every error and in [`Path::file`].
    ///
    /// # Errors
    /// As [`Path::parse`], naming `file`.
    pub fn parse_named(text: &str, file: &str, registry: &Registry) -> Result<Path, PathError> {
        let mut path = Self::parse(text, registry).map_err(|e| e.in_file(file))?;
        path.file = file.to_string();
        Ok(path)
    }

    /// Reads and parses a file (`-`: standard input), at most [`MAX_PATH_BYTES`] bytes of
    /// UTF-8 text (a leading byte-order mark is skipped).
    ///
    /// # Errors
    /// [`PathError::Io`] (unreadable, too large), [`PathError::Parse`] (not UTF-8, with the
    /// line and column of the first bad byte; malformed RON), naming the file.
    pub fn load(file: &std::path::Path, registry: &Registry) -> Result<Path, PathError> {
        use std::io::Read;
        let stdin = file.as_os_str() == "-";
        let name = if stdin {
            "<stdin>".to_string()
        } else {
            cov_core::one_line(&file.display().to_string())
        };
        let io = |message: String| PathError::Io {
            file: name.clone(),
            message,
        };
        let mut bytes = Vec::new();
        let read = if stdin {
            std::io::stdin()
                .lock()
                .take(MAX_PATH_BYTES + 1)
                .read_to_end(&mut bytes)
        } else {
            std::fs::File::open(file).and_then(|f| f.take(MAX_PATH_BYTES + 1).read_to_end(&mut bytes))
        };
        read.map_err(|e| io(e.to_string()))?;
        if bytes.len() as u64 > MAX_PATH_BYTES {
            return Err(io(format!(
                "more than {MAX_PATH_BYTES} bytes; path files are read up to {} MiB",
                MAX_PATH_BYTES >> 20
            )));
        }
        let text = utf8(&bytes, &name)?;
        Self::parse_named(text.strip_prefix('\u{feff}').unwrap_or(text), &name, registry)
    }

    /// Union of what the source and every operator need.
    pub fn requires(&self) -> AxisSet {
        self.source.requires().union(self.operators.requires())
    }

    /// The layout the path is traced in: the declared one, or the smallest that holds what
    /// every operator needs. The flag says whether it was inferred.
    ///
    /// # Errors
    /// A declared layout that lacks an axis some operator needs (naming both).
    pub fn resolve_layout(&self) -> Result<(usize, bool), PathError> {
        let needed = self.requires();
        let Some(n) = self.layout else {
            return Ok((needed.smallest_layout(), true));
        };
        let have = layout_set(n);
        let invalid = |at: Option<(usize, usize)>, message: String| PathError::Invalid {
            file: self.file.clone(),
            at,
            message,
        };
        if let Source::Matrix { rows } = &self.source
            && rows.len() != n
        {
            return Err(invalid(
                None,
                format!("the source matrix is {0}×{0} but the layout is {n}", rows.len()),
            ));
        }
        for (i, op) in self.operators.operators().enumerate() {
            if let Some(axis) = op.requires().iter().find(|a| !have.contains(*a)) {
                return Err(invalid(
                    self.positions.get(i).copied(),
                    format!(
                        "step {i} ({}) needs axis `{axis}`, which layout {n} ({}) does not have",
                        op.name(),
                        axes_string(n)
                    ),
                ));
            }
        }
        if let Some(axis) = self.source.requires().iter().find(|a| !have.contains(*a)) {
            return Err(invalid(
                None,
                format!(
                    "the source needs axis `{axis}`, which layout {n} ({}) does not have",
                    axes_string(n)
                ),
            ));
        }
        Ok((n, false))
    }
}

/// Largest path file read (bytes): 16 MiB, far above any hand-written or generated path
/// (a 10⁶-operator path is about 25 MB of `Travel(distance: 1.0)`: split it).
pub const MAX_PATH_BYTES: u64 = 16 << 20;

/// `bytes` as UTF-8, or a parse error at the line and column of the first invalid byte.
fn utf8<'a>(bytes: &'a [u8], name: &str) -> Result<&'a str, PathError> {
    std::str::from_utf8(bytes).map_err(|_| {
        let (line, col, bad) = cov_core::utf8_error_at(bytes).unwrap_or((1, 1, 0));
        let utf16 = bytes.starts_with(&[0xFF, 0xFE]) || bytes.starts_with(&[0xFE, 0xFF]);
        PathError::Parse {
            file: name.to_string(),
            line,
            col,
            message: if utf16 {
                "the file is UTF-16 text; path files are UTF-8".into()
            } else {
                format!("not UTF-8 text: byte 0x{bad:02X} cannot start or continue a character")
            },
        }
    })
}

/// The axis names of layout `n`, comma-separated.
pub(crate) fn axes_string(n: usize) -> String {
    layout_axes(n)
        .unwrap_or(&[])
        .iter()
        .map(|a| a.name())
        .collect::<Vec<_>>()
        .join(",")
}
