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
}

/// Every element of every operator list, in the order of the text.
pub(crate) fn operator_elements(text: &str) -> Vec<Element> {
    let chars: Vec<char> = text.chars().collect();
    let mut pos = Vec::with_capacity(chars.len());
    let (mut line, mut col) = (1usize, 1usize);
    for &c in &chars {
        pos.push((line, col));
        if c == '\n' {
            line += 1;
            col = 1;
        } else {
            col += 1;
        }
    }
    // Stack of open brackets: true for an operator list.
    let mut stack: Vec<bool> = Vec::new();
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
                top: stack.iter().filter(|&&b| b).count() == 1,
                bare: j > i && chars.get(k) != Some(&'('),
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
                expect_element = list;
            }
            ')' | '}' | ']' => {
                stack.pop();
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
    fn finds_nested_and_bare_operators() {
        let t = "Path(source: X, operators: [Mirror, Moving(velocity: [1], operators: [Diffuse /* c */ (), Mirror]), Travel(distance: 1)])";
        let e = operator_elements(t);
        let bare: Vec<bool> = e.iter().map(|e| e.bare).collect();
        let top: Vec<bool> = e.iter().map(|e| e.top).collect();
        assert_eq!(bare, vec![true, false, false, true, false]);
        assert_eq!(top, vec![true, true, false, false, true]);
        assert_eq!(operator_positions(t).len(), 3);
    }
}
