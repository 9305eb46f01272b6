//! pbrt-v4's scene-file tokens: quoted strings (with `\"`, `\\`, `\n`, `\t` escapes), numbers,
//! `[` and `]`, bare words (directives, `true`/`false`), `#` comments to the end of the line.
//! Each token carries its file, line and column (1-based, columns in characters).

use std::rc::Rc;

/// Where a token starts.
#[derive(Clone, Debug, PartialEq)]
pub struct Loc {
    pub file: Rc<str>,
    pub line: u32,
    pub column: u32,
}

impl std::fmt::Display for Loc {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}:{}", self.file, self.line, self.column)
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum Kind {
    /// A quoted string, unescaped.
    Str(String),
    Number(f64),
    Open,
    Close,
    /// A bare word: a directive or `true`/`false`.
    Word(String),
}

#[derive(Clone, Debug, PartialEq)]
pub struct Token {
    pub kind: Kind,
    pub loc: Loc,
}

/// The longest token accepted (a string, a number, a word): far past any file name.
pub const MAX_TOKEN_CHARS: usize = 1 << 16;

/// Splits `text` into tokens; `file` names it in locations. An error is `FILE:LINE:COLUMN: why`.
pub fn tokenize(text: &str, file: &str) -> Result<Vec<Token>, String> {
    let file: Rc<str> = Rc::from(file);
    let mut tokens = Vec::new();
    let mut chars = text.chars().peekable();
    let (mut line, mut column) = (1u32, 1u32);
    // Advances past one character, keeping the position.
    macro_rules! bump {
        () => {{
            let c = chars.next();
            if c == Some('\n') {
                line += 1;
                column = 1;
            } else if c.is_some() {
                column += 1;
            }
            c
        }};
    }
    while let Some(&c) = chars.peek() {
        let loc = Loc { file: file.clone(), line, column };
        let too_long = |what: &str| format!("{loc}: {what} longer than {MAX_TOKEN_CHARS} characters");
        match c {
            c if c.is_whitespace() => {
                bump!();
            }
            '#' => {
                while chars.peek().is_some_and(|&c| c != '\n') {
                    bump!();
                }
            }
            '[' => {
                bump!();
                tokens.push(Token { kind: Kind::Open, loc });
            }
            ']' => {
                bump!();
                tokens.push(Token { kind: Kind::Close, loc });
            }
            '"' => {
                bump!();
                let mut s = String::new();
                loop {
                    match bump!() {
                        None => {
                            return Err(format!(
                                "{loc}: a string that is never closed (no '\"' before the end of the file)"
                            ))
                        }
                        Some('\n') => {
                            return Err(format!("{loc}: a string that runs past the end of its line (a missing '\"'?)"))
                        }
                        Some('"') => break,
                        Some('\\') => match bump!() {
                            Some('n') => s.push('\n'),
                            Some('t') => s.push('\t'),
                            Some('b') => s.push('\u{8}'),
                            Some('f') => s.push('\u{c}'),
                            Some('r') => s.push('\r'),
                            Some(e @ ('\\' | '"' | '\'')) => s.push(e),
                            other => {
                                return Err(format!(
                                    "{}:{}:{}: unknown escape '\\{}' in a string",
                                    loc.file,
                                    line,
                                    column.saturating_sub(1),
                                    other.map(String::from).unwrap_or_default()
                                ))
                            }
                        },
                        Some(ch) => s.push(ch),
                    }
                    if s.len() > MAX_TOKEN_CHARS {
                        return Err(too_long("a string"));
                    }
                }
                tokens.push(Token { kind: Kind::Str(s), loc });
            }
            _ => {
                let mut word = String::new();
                while let Some(&c) = chars.peek() {
                    if c.is_whitespace() || matches!(c, '[' | ']' | '"' | '#') {
                        break;
                    }
                    word.push(c);
                    bump!();
                    if word.len() > MAX_TOKEN_CHARS {
                        return Err(too_long("a word"));
                    }
                }
                let first = word.chars().next().unwrap_or(' ');
                let kind = if first.is_ascii_digit() || matches!(first, '-' | '+' | '.') {
                    let v: f64 = word.parse().map_err(|_| format!("{loc}: '{}' is not a number", short(&word)))?;
                    if !v.is_finite() {
                        return Err(format!("{loc}: the number '{}' is not finite", short(&word)));
                    }
                    Kind::Number(v)
                } else if first.is_alphabetic() || first == '_' {
                    Kind::Word(word)
                } else {
                    return Err(format!("{loc}: unexpected character '{first}'"));
                };
                tokens.push(Token { kind, loc });
            }
        }
    }
    Ok(tokens)
}

/// A word or value shortened for messages.
pub fn short(s: &str) -> String {
    if s.chars().count() > 40 {
        format!("{}…", s.chars().take(40).collect::<String>())
    } else {
        s.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tokens_with_positions() {
        let t = tokenize("LookAt 0 1 -2.5e1 # eye\n  \"float fov\" [ 30 ]\n\"a\\\"b\"", "s.pbrt").unwrap();
        let kinds: Vec<&Kind> = t.iter().map(|t| &t.kind).collect();
        assert_eq!(
            kinds,
            vec![
                &Kind::Word("LookAt".into()),
                &Kind::Number(0.0),
                &Kind::Number(1.0),
                &Kind::Number(-25.0),
                &Kind::Str("float fov".into()),
                &Kind::Open,
                &Kind::Number(30.0),
                &Kind::Close,
                &Kind::Str("a\"b".into()),
            ]
        );
        assert_eq!((t[4].loc.line, t[4].loc.column), (2, 3));
        assert_eq!(t[8].loc.to_string(), "s.pbrt:3:1");
    }

    #[test]
    fn errors_name_the_position() {
        assert!(tokenize("Shape \"sphere", "a").unwrap_err().starts_with("a:1:7: a string that is never closed"));
        assert!(tokenize("\n  1.2.3", "a").unwrap_err().starts_with("a:2:3: '1.2.3' is not a number"));
        assert!(tokenize("1e999", "a").unwrap_err().contains("not finite"));
        assert!(tokenize("  {", "a").unwrap_err().starts_with("a:1:3: unexpected character"));
    }
}
