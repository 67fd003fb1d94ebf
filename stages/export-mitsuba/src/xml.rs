//! The two XML escapes the scene writer needs.

/// `value` as a double-quoted XML attribute value, quotes included.
pub fn attribute(value: &str) -> String {
    let mut s = String::with_capacity(value.len() + 2);
    s.push('"');
    for c in value.chars() {
        match c {
            '&' => s.push_str("&amp;"),
            '<' => s.push_str("&lt;"),
            '>' => s.push_str("&gt;"),
            '"' => s.push_str("&quot;"),
            '\'' => s.push_str("&apos;"),
            '\n' => s.push_str("&#10;"),
            c => s.push(c),
        }
    }
    s.push('"');
    s
}

/// `text` as an XML comment block (with a line break after it). A comment
/// may not hold `--` nor end in `-`: every `-` that follows a `-` is
/// written as `&#45;` (comments are not entity-decoded, so the text stays
/// readable and unambiguous), and a trailing `-` gets a space after it.
pub fn comment(text: &str) -> String {
    let mut body = String::with_capacity(text.len());
    let mut previous_hyphen = false;
    for c in text.chars() {
        if c == '-' && previous_hyphen {
            body.push_str("&#45;");
        } else {
            body.push(c);
        }
        previous_hyphen = c == '-';
    }
    if body.ends_with('-') {
        body.push(' ');
    }
    format!("<!--\n{body}\n-->\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn comments_never_hold_two_hyphens() {
        let c = comment("a --mesh b --- c-");
        let inner = &c["<!--".len()..c.len() - "-->\n".len()];
        assert!(!inner.contains("--"), "{inner}");
        assert!(!inner.trim_end_matches('\n').ends_with('-'));
        assert_eq!(attribute("a\"<&>'"), "\"a&quot;&lt;&amp;&gt;&apos;\"");
    }
}
