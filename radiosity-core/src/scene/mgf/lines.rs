//! Splits MGF text into entities: one logical line each (a trailing backslash continues a line onto
//! the next), broken into words; comment lines (first word starting with `#`) and blank lines are
//! dropped.

/// One entity: its words (the first is the entity name) and the line on which it starts.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Entity {
    /// 1-based number of the first physical line of the entity.
    pub line: usize,
    /// The words, split at ASCII whitespace.
    pub words: Vec<Box<str>>,
}

/// The entities of `text`, in file order.
pub(super) fn split(text: &str) -> Vec<Entity> {
    let mut out = Vec::new();
    // A logical line being continued: (first line number, text so far).
    let mut pending: Option<(usize, String)> = None;
    for (idx, raw) in text.lines().enumerate() {
        let line_no = idx + 1;
        let (start, mut buf) = pending.take().unwrap_or_else(|| (line_no, String::new()));
        match raw.trim_end().strip_suffix('\\') {
            Some(body) => {
                buf.push_str(body);
                buf.push(' ');
                pending = Some((start, buf));
            }
            None => {
                buf.push_str(raw);
                push_entity(&mut out, start, &buf);
            }
        }
    }
    if let Some((start, buf)) = pending {
        push_entity(&mut out, start, &buf);
    }
    out
}

fn push_entity(acc: &mut Vec<Entity>, line: usize, text: &str) {
    let words: Vec<Box<str>> = text.split_ascii_whitespace().map(Box::from).collect();
    if words.first().is_some_and(|w| !w.starts_with('#')) {
        acc.push(Entity { line, words });
    }
}

/// A finite floating-point number, or `None` when `word` is not one.
#[must_use]
pub(super) fn parse_f64(word: &str) -> Option<f64> {
    word.parse::<f64>().ok().filter(|v| v.is_finite())
}

/// An integer, or `None` when `word` is not one.
#[must_use]
pub(super) fn parse_int(word: &str) -> Option<i64> {
    word.strip_prefix('+').unwrap_or(word).parse::<i64>().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn continuation_comments_and_line_numbers() {
        let text = "# comment\nv a =\n\tp 1 2 \\\n 3\n\n#x \\\n still comment\nf a b c\r\n";
        let entities = split(text);
        let got: Vec<(usize, Vec<&str>)> = entities.iter().map(|e| (e.line, e.words.iter().map(|w| &**w).collect())).collect();
        assert_eq!(got, vec![(2, vec!["v", "a", "="]), (3, vec!["p", "1", "2", "3"]), (8, vec!["f", "a", "b", "c"])]);
    }

    #[test]
    fn numbers() {
        assert_eq!(parse_f64(".5"), Some(0.5));
        assert_eq!(parse_f64("1."), Some(1.0));
        assert_eq!(parse_f64("-2.5e-3"), Some(-2.5e-3));
        assert_eq!(parse_f64("nan"), None);
        assert_eq!(parse_f64("1e999"), None);
        assert_eq!(parse_f64("x"), None);
        assert_eq!(parse_int("+3"), Some(3));
        assert_eq!(parse_int("3.0"), None);
    }
}
