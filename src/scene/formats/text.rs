//! Small helpers shared by the line-based parsers (OBJ, MTL, PLY, TOML).

/// The 1-based line number of byte `offset` in `text`.
pub fn line_at(text: &[u8], offset: usize) -> usize {
    1 + text[..offset.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
}

/// Parses a finite `f32`; the error says what was expected and what was found.
pub fn finite_f32(token: &str, what: &str) -> Result<f32, String> {
    match token.parse::<f32>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(format!("{what} {token:?} is not a finite number")),
        Err(_) => Err(format!("{what} {token:?} is not a number")),
    }
}

/// Splits `bytes` into lines (without the `\n` or `\r\n`), numbered from 1,
/// each checked to be UTF-8.
pub fn numbered_lines(bytes: &[u8]) -> impl Iterator<Item = (usize, Result<&str, String>)> {
    bytes.split(|&b| b == b'\n').enumerate().map(|(i, line)| {
        let line = line.strip_suffix(b"\r").unwrap_or(line);
        let text = std::str::from_utf8(line)
            .map_err(|e| format!("invalid UTF-8 at byte {} of the line", e.valid_up_to()));
        (i + 1, text)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_numbers_count_newlines_before_the_offset() {
        let text = b"a\nbb\nccc";
        assert_eq!(line_at(text, 0), 1);
        assert_eq!(line_at(text, 2), 2);
        assert_eq!(line_at(text, 6), 3);
    }

    #[test]
    fn non_finite_numbers_are_rejected() {
        assert_eq!(finite_f32("1.5", "x"), Ok(1.5));
        assert!(finite_f32("nan", "x").unwrap_err().contains("finite"));
        assert!(finite_f32("1e40", "x").unwrap_err().contains("finite"));
        assert!(finite_f32("abc", "x").unwrap_err().contains("not a number"));
    }

    #[test]
    fn lines_are_numbered_and_checked_for_utf8() {
        let lines: Vec<_> = numbered_lines(b"ok\r\n\xff\n").collect();
        assert_eq!(lines[0], (1, Ok("ok")));
        assert!(lines[1].1.is_err());
        assert_eq!(lines[1].0, 2);
    }
}
