//! A light scan of a path file for its operator lists (the value of every `operators:`
//! key, nested ones included), skipping comments and strings. It gives evaluation errors
//! (which happen after ron has finished) the line and column of the failing step, and
//! tells the parser which operators are written as a bare name (`Mirror`) rather than
//! with parentheses (`Mirror()`), in the order ron meets them.

/// One element of an operator list.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Element {
    /// 1-based line.
    pub line: usize,
    /// 1-based column (in characters).
    pub col: usize,
    /// Whether it is in the path's own (top-level) list.
    pub top: bool,
    /// Whether its name is not followed by `(`.
    pub bare: bool,
    /// Number of operator lists around it (1: the path's own).
    pub depth: usize,
}

/// Deepest nesting of operator lists a path may have (a `Moving` inside a `Moving` … 16
/// lists deep). Deeper files are refused before parsing, with the position of the first
/// element too deep; the parser's own recursion limit (128 levels, about 23 lists) stays
/// a backstop that is never reached.
pub const MAX_NESTING: usize = 16;

/// Most operators a path may hold, nested ones included. Each step's Σ is kept for the
/// report, and `eval --json` writes them all: at 2.4 million steps (a 16 MiB file of
/// `Mirror`s) that took 4 GB. A chain this long is a loop a program should write, not a
/// file; the stiff suite's longest chain has 10⁴.
pub const MAX_OPERATORS: usize = 100_000;

/// `chars` with every comment blanked (its line breaks kept) and every string's contents
/// replaced by `x`, so that brackets, colons and commas written there do not count as
/// the file's structure; every character keeps its position.
fn code_of(chars: &[char]) -> Vec<char> {
    let mut out = chars.to_vec();
    let mut i = 0;
    while i < chars.len() {
        if let Some(next) = skip_comment(chars, i) {
            for c in &mut out[i..next.min(chars.len())] {
                if *c != '\n' {
                    *c = ' ';
                }
            }
            i = next;
        } else if chars[i] == '"' {
            let next = skip_string(chars, i).min(chars.len());
            for c in &mut out[i + 1..next.saturating_sub(1).max(i + 1)] {
                if *c != '\n' {
                    *c = 'x';
                }
            }
            i = next;
        } else {
            i += 1;
        }
    }
    out
}

/// `(line, col)`, 1-based, of every character of `chars`.
fn char_positions(chars: &[char]) -> Vec<(usize, usize)> {
    let mut pos = Vec::with_capacity(chars.len());
    let (mut line, mut col) = (1usize, 1usize);
    for &c in chars {
        pos.push((line, col));
        if c == '\n' {
            line += 1;
            col = 1;
        } else {
            col += 1;
        }
    }
    pos
}

/// Where the field `name` is written inside the operator whose closing parenthesis is at
/// (or just before) `(line, col)`: ron reports errors of a whole operator (a parameter out
/// of range) at its end; this finds `name:` at the operator's own level. `None` when the
/// position is not the end of an operator or the field is not written there (a default).
pub(crate) fn field_position(text: &str, line: usize, col: usize, name: &str) -> Option<(usize, usize)> {
    let chars = code_of(&text.chars().collect::<Vec<char>>());
    let pos = char_positions(&chars);
    let mut close = pos.iter().position(|&p| p == (line, col))?;
    // ron may point just past the parenthesis.
    while close > 0 && chars[close] != ')' && (chars[close].is_whitespace() || chars[close] == ',') {
        close -= 1;
    }
    if chars[close] != ')' {
        return None;
    }
    // The matching `(`, counting brackets backwards.
    let mut depth = 0usize;
    let mut open = None;
    for i in (0..close).rev() {
        match chars[i] {
            ')' | ']' | '}' => depth += 1,
            '(' | '[' | '{' if depth == 0 => {
                open = Some(i);
                break;
            }
            '(' | '[' | '{' => depth -= 1,
            _ => {}
        }
    }
    let open = open?;
    // A parameter `values[2]` is element 2 of the list `values`.
    let (name, element) = match name.split_once('[') {
        Some((n, rest)) => (n, rest.trim_end_matches(']').parse::<usize>().ok()),
        None => (name, None),
    };
    // `name` followed by `:`, at the operator's own level first, else inside a nested
    // parameter (a `Tabulated(...)` phase).
    let mut found: Option<(usize, usize)> = None; // (level, index after the `:`)
    let mut i = open + 1;
    let mut level = 0usize;
    while i < close {
        if let Some(next) = skip_comment(&chars, i) {
            i = next;
            continue;
        }
        let c = chars[i];
        if c == '"' {
            i = skip_string(&chars, i);
            continue;
        }
        match c {
            '(' | '[' | '{' => level += 1,
            ')' | ']' | '}' => level = level.saturating_sub(1),
            _ => {}
        }
        let starts = (c.is_alphabetic() || c == '_')
            && (i == 0 || !(chars[i - 1].is_alphanumeric() || chars[i - 1] == '_'));
        if starts {
            let mut j = i;
            while j < close && (chars[j].is_alphanumeric() || chars[j] == '_') {
                j += 1;
            }
            let word: String = chars[i..j].iter().collect();
            let mut k = j;
            while k < close && chars[k].is_whitespace() {
                k += 1;
            }
            if word == name && chars.get(k) == Some(&':') && found.is_none_or(|(l, _)| level < l) {
                found = Some((level, i));
            }
            i = j;
            continue;
        }
        i += 1;
    }
    let (_, at) = found?;
    let Some(k) = element else {
        return Some(pos[at]);
    };
    // Element k of the list after `name:`: count the commas at the list's own level.
    let mut i = at;
    while i < close && chars[i] != '[' {
        i += 1;
    }
    let mut depth = 0usize;
    let mut index = 0usize;
    let mut j = i + 1;
    while j < close {
        match chars[j] {
            '(' | '[' | '{' => depth += 1,
            ')' | '}' => depth = depth.saturating_sub(1),
            ']' if depth == 0 => break,
            ']' => depth -= 1,
            ',' if depth == 0 => index += 1,
            c if index == k && depth == 0 && !c.is_whitespace() => return Some(pos[j]),
            _ => {}
        }
        j += 1;
    }
    Some(pos[at])
}

/// Whether `text` holds nothing but blanks and comments (a leading byte-order mark not
/// counted).
pub fn blank_or_comment(text: &str) -> bool {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    code_of(&text.chars().collect::<Vec<char>>())
        .iter()
        .all(|c| c.is_whitespace())
}

/// The field whose value ron stopped at in RON `text` (a path's or a scene's), `(line,
/// col)` (1-based, as ron reports it) being in that value or just before it, where ron
/// reports a value of the wrong type, or at the closing parenthesis of a tuple it
/// refused: the nearest `name:` before the value at its own bracket level, the name's
/// position, and the value as written (cut after 40 characters where a word or a number
/// ends). An optional value written
/// `Some(…)` is the field's value whole: a position inside it is the field's. `None`
/// when no `name:` stands between the position and the bracket that opens its level (an
/// entry of a list). A leading byte-order mark is not counted, as ron does not count it.
pub fn field_at(text: &str, line: usize, col: usize) -> Option<(String, (usize, usize), String)> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let written: Vec<char> = text.chars().collect();
    let chars = code_of(&written);
    let pos = char_positions(&chars);
    let (start, end, colon) = field_span(&chars, &pos, line, col)?;
    let name: String = chars[start..end].iter().collect();
    Some((name, pos[start], value_from(&written, &chars, colon + 1)))
}

/// Where the value of [`field_at`]'s field starts (line, column, 1-based): its first
/// character after the colon that is not blank or a comment. A position on an element of a
/// tuple or a list, which has no `name:` of its own ([`element_at`]), gives where the
/// tuple or list starts: its opening bracket.
pub fn value_position(text: &str, line: usize, col: usize) -> Option<(usize, usize)> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let chars = code_of(&text.chars().collect::<Vec<char>>());
    let pos = char_positions(&chars);
    if let Some((_, _, colon)) = field_span(&chars, &pos, line, col) {
        let v = (colon + 1..chars.len()).find(|&v| !chars[v].is_whitespace())?;
        return Some(pos[v]);
    }
    let at = pos.iter().position(|&p| p >= (line, col)).unwrap_or(chars.len());
    let (open, _) = open_bracket(&chars, at)?;
    Some(pos[open])
}

/// [`field_at`]'s field in `chars` (a [`code_of`], `pos` its positions): the indices of
/// the start and the end of its name and of its colon.
fn field_span(
    chars: &[char],
    pos: &[(usize, usize)],
    line: usize,
    col: usize,
) -> Option<(usize, usize, usize)> {
    let mut at = pos.iter().position(|&p| p >= (line, col)).unwrap_or(chars.len());
    // A tuple refused at its closing parenthesis: its field precedes the opening one.
    if chars.get(at) == Some(&')') {
        let mut depth = 0usize;
        while at > 0 {
            at -= 1;
            match chars[at] {
                ')' => depth += 1,
                '(' if depth == 0 => break,
                '(' => depth -= 1,
                _ => {}
            }
        }
    }
    let mut depth = 0usize;
    let mut i = at;
    let colon = loop {
        if i == 0 {
            return None;
        }
        i -= 1;
        match chars[i] {
            ')' | ']' | '}' => depth += 1,
            // `Some(` opens no level of its own: the field is the one it is the value of.
            '(' if depth == 0 && {
                let (a, b) = word_before(chars, i);
                chars[a..b] == ['S', 'o', 'm', 'e']
            } => {}
            '(' | '[' | '{' if depth == 0 => return None,
            '(' | '[' | '{' => depth -= 1,
            ':' if depth == 0 => break i,
            _ => {}
        }
    };
    let (start, end) = word_before(chars, colon);
    if start == end || !(chars[start].is_alphabetic() || chars[start] == '_') {
        return None;
    }
    Some((start, end, colon))
}

/// The indices of the start and the end of the word (letters, digits, `_`) that ends
/// right before index `i` of `chars`, blanks between them skipped (empty: no word).
fn word_before(chars: &[char], i: usize) -> (usize, usize) {
    let mut end = i;
    while end > 0 && chars[end - 1].is_whitespace() {
        end -= 1;
    }
    let mut start = end;
    while start > 0 && (chars[start - 1].is_alphanumeric() || chars[start - 1] == '_') {
        start -= 1;
    }
    (start, end)
}

/// The value written from `v` in `written` (`chars`: its [`code_of`], comments blanked
/// and strings' contents replaced), blanks before it skipped, to the comma, line end or
/// closing bracket that ends it at its own level: cut after 40 characters where a word or
/// a number ends, comments and runs of blanks read as one space, trailing blanks trimmed.
fn value_from(written: &[char], chars: &[char], mut v: usize) -> String {
    while v < chars.len() && chars[v].is_whitespace() {
        v += 1;
    }
    let mut depth = 0usize;
    let mut w = v;
    while w < chars.len() {
        match chars[w] {
            '(' | '[' | '{' => depth += 1,
            ')' | ']' | '}' if depth == 0 => break,
            ')' | ']' | '}' => depth -= 1,
            ',' | '\n' if depth == 0 => break,
            _ => {}
        }
        w += 1;
    }
    // As written, but a comment (blank in `chars`) and every run of blanks read as one
    // space, so that a value written over several lines echoes on one.
    let mut out = String::new();
    // Characters in `out`, counted as they come (counting `out` each time took a number of
    // a million digits quadratic time).
    let mut n = 0usize;
    for (c, code) in written[v..w].iter().zip(&chars[v..w]) {
        if code.is_whitespace() {
            if !out.ends_with(' ') {
                out.push(' ');
                n += 1;
            }
        } else {
            out.push(*c);
            n += 1;
        }
        // Past 40 characters, at the first blank or bracket: a number of 5,000 digits is
        // read whole, so that what it is (too large for a float) can be told.
        if n >= 40 && !code.is_alphanumeric() && !matches!(code, '.' | '_' | '-' | '+') {
            break;
        }
    }
    out.trim_end().to_string()
}

/// A field as [`field_at`] finds it: its name, the name's position (line, column, 1-based)
/// and its value as written.
pub type Field = (String, (usize, usize), String);

/// The element of a tuple or list that ron stopped at in RON `text`, `(line, col)`
/// (1-based) being in it or just before it (`(0.0, "a", 1.3)` refused at `"a"`, or at a
/// fourth value): the field the tuple or list is the value of (as [`field_at`] gives it:
/// name, name's position, the value as written), the element's index from 0, and the
/// element as written ([`field_at`]'s reading). `None` outside a tuple in parentheses or
/// a list in brackets, or for one that is no field's value.
pub fn element_at(text: &str, line: usize, col: usize) -> Option<(Field, usize, String)> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let written: Vec<char> = text.chars().collect();
    let chars = code_of(&written);
    let pos = char_positions(&chars);
    let at = pos.iter().position(|&p| p >= (line, col)).unwrap_or(chars.len());
    let (open, index) = open_bracket(&chars, at)?;
    let (l, c) = pos[open];
    let field = field_at(text, l, c)?;
    let element = value_from(&written, &chars, at);
    Some((field, index, element))
}

/// The tuple's or list's opening bracket before index `at` of `chars` (a [`code_of`]) at
/// its own level, and the index of the element `at` is in (commas between them); `None`
/// inside a map or outside any bracket.
fn open_bracket(chars: &[char], at: usize) -> Option<(usize, usize)> {
    let (mut depth, mut index, mut i) = (0usize, 0usize, at);
    loop {
        if i == 0 {
            return None;
        }
        i -= 1;
        match chars[i] {
            ')' | ']' | '}' => depth += 1,
            '(' | '[' if depth == 0 => return Some((i, index)),
            '{' if depth == 0 => return None,
            '(' | '[' | '{' => depth -= 1,
            ',' if depth == 0 => index += 1,
            _ => {}
        }
    }
}

/// Where the bracket left open before index `at` of `chars` (a [`code_of`]) is, and the
/// bracket that closes it, when `chars[at]` is a closing bracket: `None` for any other
/// character, or outside brackets.
fn open_for_close(chars: &[char], at: usize) -> Option<(usize, char)> {
    if !matches!(chars.get(at)?, ')' | ']' | '}') {
        return None;
    }
    let mut depth = 0usize;
    for i in (0..at).rev() {
        match chars[i] {
            ')' | ']' | '}' => depth += 1,
            '(' if depth == 0 => return Some((i, ')')),
            '[' if depth == 0 => return Some((i, ']')),
            '{' if depth == 0 => return Some((i, '}')),
            '(' | '[' | '{' => depth -= 1,
            _ => {}
        }
    }
    None
}

/// The first whitespace character other than an ASCII space, tab or line break (a
/// no-break space U+00A0, an em space, an ideographic space…) outside comments and strings,
/// before `(line, col)` or in the whitespace just after it: RON does not read it as space, and reports whatever it
/// stopped at instead (a number "expected", a comma). Its position and a message naming it.
pub fn odd_space_before(text: &str, line: usize, col: usize) -> Option<((usize, usize), String)> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let chars = code_of(&text.chars().collect::<Vec<char>>());
    let pos = char_positions(&chars);
    // Up to the error and the run of whitespace that follows it (ron may stop just before
    // the odd character).
    let mut end = pos.iter().position(|&p| p > (line, col)).unwrap_or(chars.len());
    while end < chars.len() && (chars[end].is_whitespace() || invisible(chars[end])) {
        end += 1;
    }
    let (i, c) = chars[..end]
        .iter()
        .enumerate()
        .find(|(_, c)| (c.is_whitespace() || invisible(**c)) && !matches!(c, ' ' | '\t' | '\n' | '\r'))?;
    let code = u32::from(*c);
    let what = if invisible(*c) {
        format!("an invisible U+{code:04X} character")
    } else {
        format!("a U+{code:04X} space character")
    };
    Some((
        pos[i],
        format!(
            "{what} here: a file reads only plain spaces, tabs and line breaks between values (it often comes from pasting text)"
        ),
    ))
}

/// Whether `c` is a character of no width that is not whitespace to Unicode (a zero-width
/// space U+200B, a zero-width joiner or non-joiner, a word joiner U+2060, a byte-order
/// mark inside the text): invisible where it is pasted, and no blank to ron.
fn invisible(c: char) -> bool {
    matches!(c, '\u{200B}'..='\u{200D}' | '\u{2060}' | '\u{FEFF}')
}

/// The string that ron's error at `(line, col)` of `text` follows, if it runs over a line
/// break: a name or a file path never does, so its closing `"` is missing and the string
/// ran on to the next `"`, where ron then stopped. The string's opening quote and the line
/// it ends on (1-based).
fn string_across_lines(text: &str, line: usize, col: usize) -> Option<((usize, usize), usize)> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let chars: Vec<char> = text.chars().collect();
    let pos = char_positions(&chars);
    let end = pos.iter().position(|&p| p >= (line, col)).unwrap_or(chars.len());
    let mut last = None;
    let mut i = 0;
    while i < end {
        if let Some(next) = skip_comment(&chars, i) {
            i = next;
        } else if chars[i] == '"' {
            let next = skip_string(&chars, i).min(chars.len());
            last = Some((i, next));
            i = next;
        } else {
            i += 1;
        }
    }
    let (open, next) = last?;
    let close = next.saturating_sub(1).max(open);
    chars[open..close]
        .contains(&'\n')
        .then(|| (pos[open], pos[close.min(chars.len() - 1)].0))
}

/// The first block comment of `text` that is not closed (`/*` without its `*/`; comments
/// nest), at its `/*`: ron reports it at the end of the file.
fn unclosed_comment(text: &str) -> Option<(usize, usize)> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let chars: Vec<char> = text.chars().collect();
    let pos = char_positions(&chars);
    let mut i = 0;
    while i < chars.len() {
        if let Some(next) = skip_comment(&chars, i) {
            let closed = chars[i + 1] == '/' || (next >= i + 4 && chars[next - 2..next] == ['*', '/']);
            if !closed {
                return Some(pos[i]);
            }
            i = next;
        } else if chars[i] == '"' {
            i = skip_string(&chars, i);
        } else {
            i += 1;
        }
    }
    None
}

/// The first backslash in the string at or after `(line, col)` of `text` that starts no
/// escape ron reads (`\\`, `\"`, `\'`, `\n`, `\r`, `\t`, `\0`, `\x…`, `\u{…}`), where
/// ron reports it at the string's start: its position and the two characters.
fn bad_escape(text: &str, line: usize, col: usize) -> Option<((usize, usize), String)> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let chars: Vec<char> = text.chars().collect();
    let pos = char_positions(&chars);
    let start = pos.iter().position(|&p| p >= (line, col)).unwrap_or(chars.len());
    // The string holding the position, or the next one.
    let open = (0..=start.min(chars.len().saturating_sub(1)))
        .rev()
        .find(|&i| chars[i] == '"')
        .filter(|&i| skip_string(&chars, i) > start)
        .or_else(|| (start..chars.len()).find(|&i| chars[i] == '"'))?;
    let end = skip_string(&chars, open).min(chars.len());
    let mut i = open + 1;
    while i + 1 < end {
        if chars[i] == '\\' {
            let c = chars[i + 1];
            if !matches!(c, '\'' | '"' | '\\' | 'n' | 'r' | 't' | '0' | 'x' | 'u') {
                return Some((pos[i], format!("\\{c}")));
            }
            i += 2;
        } else {
            i += 1;
        }
    }
    None
}

/// Errors of the text's tokens rather than its structure, which ron places where it
/// noticed them, not where they are, or says in a parser's words: a string whose closing
/// `"` is missing (it runs on over line breaks to the next `"`, or to the end), a
/// backslash that starts no escape (ron points at the string's start), a block comment
/// not closed (ron points at the end of the file), a typographic quote or a dash pasted
/// for `"` or `-`, a `#` comment, text after the file's value, a map's key without
/// quotes, a comma left off at a line's end (ron points at the next line).
/// `message` is ron's, at `(line, col)`; the place and the message, or `None`.
pub fn token_error(text: &str, line: usize, col: usize, message: &str) -> Option<((usize, usize), String)> {
    // The other kind of file: a scene given where a path belongs, or a path where a scene.
    for (found, words) in [
        (
            "Expected struct `Path` but found `Scene`",
            "this file holds a scene (`Scene(…)`), and this command reads a light path (`Path(…)`): render a scene with `covtrace render`",
        ),
        (
            "Expected struct `Scene` but found `Path`",
            "this file holds a light path (`Path(…)`), and this command reads a scene (`Scene(…)`): trace a path with `covtrace eval`",
        ),
    ] {
        if message.starts_with(found) {
            return Some(((line, col), words.into()));
        }
    }
    if message.starts_with("Unclosed block comment") {
        let at = unclosed_comment(text)?;
        return Some((at, "this block comment is not closed: its `*/` is missing".into()));
    }
    if message.starts_with("Unknown escape") || message.starts_with("Invalid escape") {
        let (at, escape) = bad_escape(text, line, col)?;
        return Some((
            at,
            format!(
                "`{}` is no escape a string knows: write a backslash as `\\\\` (in a file path, `/` does)",
                cov_core::echo(&escape)
            ),
        ));
    }
    if message.starts_with("Expected end of string") {
        return Some((
            (line, col),
            "this string is not closed: its closing `\"` is missing".into(),
        ));
    }
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let written: Vec<char> = text.chars().collect();
    let chars = code_of(&written);
    let pos = char_positions(&chars);
    let at = pos.iter().position(|&p| p >= (line, col)).unwrap_or(chars.len());
    // The first character at or after the error that is not blank or a comment.
    let next = (at..chars.len()).find(|&i| !chars[i].is_whitespace());
    if let Some(i) = next
        && let Some(words) = lookalike(written[i])
    {
        return Some((pos[i], words));
    }
    if message.starts_with("Expected an `#![enable(") && chars[..at.min(chars.len())].last() == Some(&'#') {
        return Some((
            pos[at - 1],
            "`#` does not start a comment: write `//` (or `/* … */`)".into(),
        ));
    }
    if message.starts_with("Non-whitespace trailing characters") {
        let i = next?;
        return Some((
            pos[i],
            format!(
                "`{}` after the end: the file's value was closed before it (a `)` too many, or a second value?)",
                cov_core::echo(&token(&written, i))
            ),
        ));
    }
    // A closing bracket of the wrong kind: the list's `]` (or a struct's `)`) left off
    // before the bracket that closes the level around it.
    if let Some(i) = next
        && let Some((open, want)) = open_for_close(&chars, i)
        && want != chars[i]
    {
        let (l, c) = pos[open];
        let (found, opened) = (chars[i], chars[open]);
        let words = match field_at(text, l, c) {
            Some((name, _, _)) => format!(
                "this `{found}` would close `{name}`, whose `{opened}` at {l}:{c} only a `{want}` closes: is its `{want}` missing?"
            ),
            None => format!(
                "this `{found}` would close the `{opened}` at {l}:{c}, which only a `{want}` closes: is a `{want}` missing before it?"
            ),
        };
        return Some((pos[i], words));
    }
    // A name where a map's key, a string, belongs: `white: Diffuse(…)`.
    if message.starts_with("Expected string")
        && let Some(i) = next
        && (chars[i].is_alphabetic() || chars[i] == '_')
    {
        let name = token(&written, i);
        let after = (i + name.chars().count()..chars.len()).find(|&j| !chars[j].is_whitespace());
        if after.is_some_and(|j| chars[j] == ':') {
            return Some((
                pos[i],
                format!(
                    "a name here is written in double quotes: `\"{}\"`",
                    cov_core::echo(&name)
                ),
            ));
        }
    }
    // A decimal comma, `radius: 1,5`: the `5` read where a field's name belongs (in a
    // tuple, `(8,8,3)`, the digit after a comma is a value, and the error is another;
    // a path's message starts with its operators' names).
    if (message.contains("Expected identifier") || message.contains("Found invalid std identifier"))
        && let Some(i) = next
        && chars[i].is_ascii_digit()
        && i >= 2
        && chars[i - 1] == ','
        && chars[i - 2].is_ascii_digit()
    {
        let start = (0..i - 1)
            .rev()
            .find(|&j| !(chars[j].is_ascii_digit() || chars[j] == '-'))
            .map_or(0, |j| j + 1);
        let number: String = written[start..i].iter().collect::<String>() + &token(&written, i);
        return Some((
            pos[start],
            format!(
                "`{}`: a comma ends a value; a decimal number is written with a point (`{}`)",
                cov_core::echo(&number),
                cov_core::echo(&number.replacen(',', ".", 1))
            ),
        ));
    }
    // A comma left off at the end of a line: said where it belongs, after the last value.
    if message == "Expected comma"
        && let Some(i) = next
        && let Some(last) = (0..at.min(chars.len()))
            .rev()
            .find(|&j| !chars[j].is_whitespace())
        && pos[last].0 < pos[i].0
    {
        let (l, c) = pos[last];
        return Some((
            (l, c + 1),
            format!(
                "a `,` is missing here, before `{}` on line {}",
                cov_core::echo(&token(&written, i)),
                pos[i].0
            ),
        ));
    }
    let (at, end) = string_across_lines(text, line, col)?;
    Some((
        at,
        format!("this string runs on to line {end}: is its closing `\"` missing?"),
    ))
}

/// What to write instead of `c`, a character pasted from a word processor that looks like
/// one the file's syntax reads: a typographic quote, a minus sign or a dash. `None` for
/// any other.
fn lookalike(c: char) -> Option<String> {
    let (what, write) = match c {
        '\u{201C}' | '\u{201D}' | '\u{201E}' | '\u{2018}' | '\u{2019}' | '\u{00AB}' | '\u{00BB}' => {
            ("a typographic quote", "\"")
        }
        '\u{2212}' => ("a typographic minus sign", "-"),
        '\u{2013}' | '\u{2014}' | '\u{2010}' | '\u{2011}' => ("a dash", "-"),
        _ => return None,
    };
    Some(format!(
        "`{c}` (U+{:04X}) is {what} (it often comes from pasting text): write `{write}`",
        u32::from(c)
    ))
}

/// The word (letters, digits, `_`, `.`, signs) that starts at index `i` of `chars`, or its
/// one character, at most 24 characters.
fn token(chars: &[char], i: usize) -> String {
    let word = |c: &char| c.is_alphanumeric() || matches!(*c, '_' | '.' | '-' | '+');
    if chars.get(i).is_some_and(word) {
        chars[i..].iter().take_while(|c| word(c)).take(24).collect()
    } else {
        chars.get(i).map(char::to_string).unwrap_or_default()
    }
}

/// The field whose value is the parenthesised struct or tuple that encloses `(line, col)`
/// of `text`: its name and where the name is written. `None` outside one, or for an
/// entry of a list.
pub fn enclosing_field(text: &str, line: usize, col: usize) -> Option<(String, (usize, usize))> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let chars = code_of(&text.chars().collect::<Vec<char>>());
    let pos = char_positions(&chars);
    let at = pos.iter().position(|&p| p >= (line, col)).unwrap_or(chars.len());
    let (open, _) = open_bracket(&chars, at)?;
    let (l, c) = pos[open];
    let (name, place, _) = field_at(text, l, c)?;
    Some((name, place))
}

/// Whether the field `name` is written after the `)` at `(line, col)` of `text`, at that
/// parenthesis's own level (before the bracket that closes the level around it): a field
/// written after a struct's closing parenthesis was meant to be inside it. `false` if no
/// `)` stands there.
pub fn written_after_close(text: &str, line: usize, col: usize, name: &str) -> bool {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let chars = code_of(&text.chars().collect::<Vec<char>>());
    let pos = char_positions(&chars);
    let Some(at) = pos.iter().position(|&p| p >= (line, col)) else {
        return false;
    };
    if chars[at] != ')' {
        return false;
    }
    let mut depth = 0usize;
    for i in at + 1..chars.len() {
        match chars[i] {
            '(' | '[' | '{' => depth += 1,
            ')' | ']' | '}' if depth == 0 => return false,
            ')' | ']' | '}' => depth -= 1,
            ':' if depth == 0 => {
                let (a, b) = word_before(&chars, i);
                if chars[a..b].iter().copied().eq(name.chars()) {
                    return true;
                }
            }
            _ => {}
        }
    }
    false
}

/// Every element of every operator list, in the order of the text.
pub(crate) fn operator_elements(text: &str) -> Vec<Element> {
    let chars: Vec<char> = text.chars().collect();
    let pos = char_positions(&chars);
    // Stack of open brackets: true for an operator list; `lists` counts the trues.
    let mut stack: Vec<bool> = Vec::new();
    let mut lists = 0usize;
    let mut out = Vec::new();
    let mut last_ident = String::new();
    let mut ident = String::new();
    let mut expect_element = false;
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if let Some(next) = skip_comment(&chars, i) {
            i = next;
            continue;
        }
        if c == '"' {
            i = skip_string(&chars, i);
            continue;
        }
        let in_list = stack.last() == Some(&true);
        if expect_element && in_list && !c.is_whitespace() && c != ']' {
            expect_element = false;
            let (line, col) = pos[i];
            // The name, then whatever follows it.
            let mut j = i;
            while j < chars.len() && (chars[j].is_alphanumeric() || chars[j] == '_') {
                j += 1;
            }
            let mut k = j;
            loop {
                while k < chars.len() && chars[k].is_whitespace() {
                    k += 1;
                }
                match skip_comment(&chars, k) {
                    Some(next) => k = next,
                    None => break,
                }
            }
            out.push(Element {
                line,
                col,
                top: lists == 1,
                bare: j > i && chars.get(k) != Some(&'('),
                depth: lists,
            });
        }
        if c.is_alphanumeric() || c == '_' {
            ident.push(c);
        } else if !ident.is_empty() {
            last_ident = std::mem::take(&mut ident);
        }
        match c {
            '(' | '{' => stack.push(false),
            '[' => {
                let list = last_ident == "operators";
                stack.push(list);
                lists += usize::from(list);
                expect_element = list;
            }
            ')' | '}' | ']' => {
                let closes_list = stack.pop() == Some(true);
                lists -= usize::from(closes_list);
            }
            ',' if in_list => expect_element = true,
            _ => {}
        }
        if !(c.is_alphanumeric() || c == '_' || c.is_whitespace() || c == ':') {
            last_ident.clear();
        }
        i += 1;
    }
    out
}

/// Line and column of each element of the top-level `operators: [...]` list.
pub(crate) fn operator_positions(text: &str) -> Vec<(usize, usize)> {
    operator_elements(text)
        .into_iter()
        .filter(|e| e.top)
        .map(|e| (e.line, e.col))
        .collect()
}

/// The index after a comment starting at `i`, if one does.
fn skip_comment(chars: &[char], i: usize) -> Option<usize> {
    if chars.get(i) != Some(&'/') {
        return None;
    }
    match chars.get(i + 1) {
        Some('/') => {
            let mut j = i;
            while j < chars.len() && chars[j] != '\n' {
                j += 1;
            }
            Some(j)
        }
        Some('*') => {
            let mut nest = 0usize;
            let mut j = i;
            while j < chars.len() {
                if chars[j] == '/' && chars.get(j + 1) == Some(&'*') {
                    nest += 1;
                    j += 2;
                } else if chars[j] == '*' && chars.get(j + 1) == Some(&'/') {
                    nest -= 1;
                    j += 2;
                    if nest == 0 {
                        return Some(j);
                    }
                } else {
                    j += 1;
                }
            }
            Some(j)
        }
        _ => None,
    }
}

/// The index after a string starting at `i` (a `"`).
fn skip_string(chars: &[char], i: usize) -> usize {
    let mut j = i + 1;
    while j < chars.len() && chars[j] != '"' {
        if chars[j] == '\\' {
            j += 1;
        }
        j += 1;
    }
    j + 1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_each_operator() {
        let text = "// c\nPath(\n  source: Gaussian(x: 0.1), /* [x] */\n  operators: [\n    Travel(distance: 1.0),\n    // Mirror,\n    Brdf(lobe: Phong(exponent: 3)), Mirror\n  ],\n)\n";
        assert_eq!(operator_positions(text), vec![(5, 5), (7, 5), (7, 37)]);
        assert!(operator_positions("Path(source: X)").is_empty());
        let t = "Path(\n    source: Matrix(rows: [[1e300, 0.0], [0.0, 1e300]]),\n    operators: [Curvature(k: 1e10)],\n)\n";
        assert_eq!(operator_positions(t), vec![(3, 17)]);
    }

    #[test]
    fn finds_a_field_of_the_operator_that_ends_at_a_position() {
        let t = "Path(\n  operators: [\n    Reflect(\n      cos_in: 0.8, // cos_out: 1\n      lobe: Phong(cos_out: 3),\n      cos_out: 2.9,\n    ),\n  ],\n)\n";
        // The `)` closing Reflect is at 7:5.
        assert_eq!(field_position(t, 7, 5, "cos_out"), Some((6, 7)));
        assert_eq!(field_position(t, 7, 5, "cos_in"), Some((4, 7)));
        assert_eq!(field_position(t, 7, 5, "turn"), None);
        assert_eq!(field_position(t, 1, 1, "cos_in"), None);
        // An element of a list inside a nested parameter.
        let t = "Scatter(\n  angle: 0.3,\n  phase: Tabulated(\n    angles: [0.0, 0.5, 0.2],\n    values: [1, 1, 1],\n  ),\n)";
        assert_eq!(field_position(t, 7, 1, "angles[2]"), Some((4, 24)));
        assert_eq!(field_position(t, 7, 1, "values"), Some((5, 5)));
    }

    /// Brackets, colons and commas inside comments and strings are not the file's
    /// structure: the field is found across a comment, and a string value is shown whole.
    #[test]
    fn a_field_is_found_across_comments_and_strings() {
        let at = |t: &str, needle: &str| {
            let i = t.find(needle).unwrap();
            let line = t[..i].matches('\n').count() + 1;
            let col = i - t[..i].rfind('\n').map_or(0, |n| n + 1) + 1;
            field_at(t, line, col)
        };
        let t = "Path(\n  operators: [Travel(distance: /* (a: b), */ \"far\")],\n)\n";
        assert_eq!(
            at(t, "\"far"),
            Some(("distance".into(), (2, 22), "\"far\"".into()))
        );
        let t = "Scene(\n  texture: \"a,b(c).png\",\n)\n";
        assert_eq!(
            at(t, "\"a,b"),
            Some(("texture".into(), (2, 3), "\"a,b(c).png\"".into()))
        );
        // A tuple refused at its closing parenthesis, a `(` in a string inside it.
        let t = "Scene(size: (\"(\", 2))";
        assert_eq!(at(t, "))"), Some(("size".into(), (1, 7), "(\"(\", 2)".into())));
        // The field's own line holds a comment with a colon after the value.
        let t = "Scene(\n  width: -3, // height: 2\n)";
        assert_eq!(at(t, "-3"), Some(("width".into(), (2, 3), "-3".into())));
    }

    /// A path of more operators than [`MAX_OPERATORS`] is refused before parsing, at the
    /// first one past the limit; one of exactly that many is not refused for its length.
    #[test]
    fn a_path_of_too_many_operators_is_refused_at_the_first_past_the_limit() {
        let path = |n: usize| {
            format!(
                "Path(source: Gaussian(x: 0.1), operators: [{}])",
                vec!["M"; n].join(",")
            )
        };
        let e = crate::Path::parse(&path(MAX_OPERATORS + 1), &crate::Registry::new())
            .unwrap_err()
            .to_string();
        let col = 44 + 2 * MAX_OPERATORS;
        assert!(
            e.contains(&format!(
                "1:{col}: the path holds 100001 operators; at most 100000"
            )),
            "{e}"
        );
        let e = crate::Path::parse(&path(MAX_OPERATORS), &crate::Registry::new())
            .unwrap_err()
            .to_string();
        assert!(e.contains("unknown operator `M`"), "{e}");
    }

    #[test]
    fn finds_nested_and_bare_operators() {
        let t = "Path(source: X, operators: [Mirror, Moving(velocity: [1], operators: [Diffuse /* c */ (), Mirror]), Travel(distance: 1)])";
        let e = operator_elements(t);
        let bare: Vec<bool> = e.iter().map(|e| e.bare).collect();
        let top: Vec<bool> = e.iter().map(|e| e.top).collect();
        assert_eq!(bare, vec![true, false, false, true, false]);
        assert_eq!(top, vec![true, true, false, false, true]);
        assert_eq!(operator_positions(t).len(), 3);
    }

    /// Token mistakes are placed where they are written: the opening quote of a string
    /// that runs over a line break, the backslash of an unknown escape, the `/*` of a
    /// comment never closed; escapes ron reads and closed comments are no mistakes.
    #[test]
    fn token_mistakes_are_placed() {
        let text = "Path(\n  source: \"a,\n  b\": 1,\n)";
        let (at, words) = token_error(text, 3, 5, "Expected colon").expect("found");
        assert_eq!(at, (2, 11));
        assert!(words.contains("runs on to line 3"), "{words}");
        // A string closed on its own line is no mistake, however the text goes on.
        assert!(token_error("X(a: \"ok \\\" \\n\", b: 1)", 1, 20, "Expected comma").is_none());
        let (at, words) =
            token_error("X(a: \"c:\\files\\x.png\")", 1, 6, "Unknown escape character").expect("found");
        assert_eq!(at, (1, 9));
        assert!(words.starts_with("`\\f` is no escape"), "{words}");
        let text = "/* a /* nested */ still open\nX(a: 1)";
        assert_eq!(
            token_error(text, 2, 8, "Unclosed block comment").map(|t| t.0),
            Some((1, 1))
        );
        let text = "/* closed */ X(a: 1) /* open";
        assert_eq!(
            token_error(text, 1, 29, "Unclosed block comment").map(|t| t.0),
            Some((1, 22))
        );
    }

    /// A `)` too many, and a field of the enclosing struct read inside an unclosed one.
    #[test]
    fn a_parenthesis_too_many_or_missing() {
        let text = "S(c: (a: 1), b: 2), d: 3)";
        assert!(written_after_close(text, 1, 11, "b"));
        assert!(!written_after_close(text, 1, 11, "d"));
        assert!(!written_after_close(text, 1, 10, "b"));
        let text = "S(\n  c: (a: 1,\n  b: 2)\n)";
        assert_eq!(enclosing_field(text, 3, 3), Some(("c".to_string(), (2, 3))));
        assert_eq!(enclosing_field("[(a: 1)]", 1, 3), None);
    }

    /// A list's `]` left off before the `)` of the struct around it is said at that `)`,
    /// naming the `[` it leaves open; a bracket of the right kind is no such mistake.
    #[test]
    fn a_closing_bracket_of_the_wrong_kind() {
        let text = "P(ops: [\n  T(d: 1),\n  W(s: 2),\n)";
        let (at, words) = token_error(text, 4, 1, "Expected identifier").expect("found");
        assert_eq!(at, (4, 1));
        assert!(
            words.contains("`)` would close `ops`, whose `[` at 1:8") && words.contains("`]` missing"),
            "{words}"
        );
        let (at, words) = token_error("P(a: (1, 2], b: 3)", 1, 11, "Expected comma").expect("found");
        assert_eq!(at, (1, 11));
        assert!(words.contains("`]` would close `a`, whose `(` at 1:6"), "{words}");
        let (_, words) = token_error("[(1, 2]", 1, 7, "Expected comma").expect("found");
        assert!(
            words.contains("`]` would close the `(` at 1:2, which only a `)` closes"),
            "{words}"
        );
        // A `)` where a `)` belongs: another mistake, not this one.
        assert!(
            token_error("P(a: (1, 2), b: 3)", 1, 12, "Expected comma")
                .is_none_or(|(_, w)| !w.contains("would close"))
        );
    }
}
