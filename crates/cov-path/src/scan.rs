//! Where each operator of a path file starts: a light scan of the `operators` list that
//! skips comments and strings. Used to give evaluation errors (which happen after ron has
//! finished) the line and column of the failing step.

/// Line and column (1-based) of each element of the top-level `operators: [...]` list.
/// Returns an empty list if the text does not have the expected shape.
pub(crate) fn operator_positions(text: &str) -> Vec<(usize, usize)> {
    let chars: Vec<char> = text.chars().collect();
    let (mut line, mut col) = (1usize, 1usize);
    let mut depth = 0usize;
    let mut i = 0;
    let mut ident = String::new();
    let mut last_ident = String::new();
    let mut list_depth: Option<usize> = None;
    let mut expect_element = false;
    let mut out = Vec::new();
    let advance = |c: char, line: &mut usize, col: &mut usize| {
        if c == '\n' {
            *line += 1;
            *col = 1;
        } else {
            *col += 1;
        }
    };
    while i < chars.len() {
        let c = chars[i];
        // Comments.
        if c == '/' && chars.get(i + 1) == Some(&'/') {
            while i < chars.len() && chars[i] != '\n' {
                advance(chars[i], &mut line, &mut col);
                i += 1;
            }
            continue;
        }
        if c == '/' && chars.get(i + 1) == Some(&'*') {
            let mut nest = 0;
            while i < chars.len() {
                if chars[i] == '/' && chars.get(i + 1) == Some(&'*') {
                    nest += 1;
                    advance(chars[i], &mut line, &mut col);
                    i += 1;
                } else if chars[i] == '*' && chars.get(i + 1) == Some(&'/') {
                    nest -= 1;
                    advance(chars[i], &mut line, &mut col);
                    i += 1;
                    if nest == 0 {
                        advance(chars[i], &mut line, &mut col);
                        i += 1;
                        break;
                    }
                }
                advance(chars[i], &mut line, &mut col);
                i += 1;
            }
            continue;
        }
        if expect_element && !c.is_whitespace() && c != ']' {
            out.push((line, col));
            expect_element = false;
        }
        // Strings.
        if c == '"' {
            advance(c, &mut line, &mut col);
            i += 1;
            while i < chars.len() && chars[i] != '"' {
                if chars[i] == '\\' {
                    advance(chars[i], &mut line, &mut col);
                    i += 1;
                }
                if i < chars.len() {
                    advance(chars[i], &mut line, &mut col);
                    i += 1;
                }
            }
            if i < chars.len() {
                advance(chars[i], &mut line, &mut col);
                i += 1;
            }
            continue;
        }
        if c.is_alphanumeric() || c == '_' {
            ident.push(c);
        } else if !ident.is_empty() {
            last_ident = std::mem::take(&mut ident);
        }
        match c {
            '(' | '{' => depth += 1,
            '[' => {
                depth += 1;
                if list_depth.is_none() && depth == 2 && last_ident == "operators" {
                    list_depth = Some(depth);
                    expect_element = true;
                }
            }
            ')' | '}' | ']' => {
                if list_depth == Some(depth) && c == ']' {
                    return out;
                }
                depth = depth.saturating_sub(1);
            }
            ',' if list_depth == Some(depth) => expect_element = true,
            _ => {}
        }
        advance(c, &mut line, &mut col);
        i += 1;
    }
    Vec::new()
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
}
