//! Tokenizer for pbrt-v4 scene text.
//!
//! The lexer walks the raw bytes of one file and yields [`Token`]s that are
//! byte ranges plus a line/column, so no token allocates: callers borrow the
//! text back with [`Lexer::bytes`] or decode a quoted string with
//! [`Lexer::string`] (which only allocates when the string has escapes).
//!
//! Token classes follow pbrt-v4's tokenizer: quoted strings (escapes
//! `\n \t \r \b \f \\ \' \"`), `[` and `]`, `#` comments to the end of the
//! line (skipped), and "words" — maximal runs of bytes that are not
//! whitespace, quotes or brackets (directive names, numbers, `true`/`false`).
//! A UTF-8 byte-order mark at the start of a file (as some Windows editors
//! write) is skipped; columns on the first line count from after it.

use std::borrow::Cow;
use std::path::Path;
use std::sync::Arc;

use crate::error::{Loc, SceneError};

/// The class of a token.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TokenKind {
    /// A directive name, number or bare word.
    Word,
    /// A quoted string; the range excludes the quotes.
    Str {
        /// Whether the string contains backslash escapes.
        escaped: bool,
    },
    /// `[`
    Open,
    /// `]`
    Close,
}

/// One token: a byte range in the lexer's text and where it starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Token {
    /// The token class.
    pub kind: TokenKind,
    /// First byte (after the opening quote for strings).
    pub start: usize,
    /// One past the last byte (before the closing quote for strings).
    pub end: usize,
    /// 1-based line.
    pub line: u32,
    /// 1-based column of the token's first byte (the quote for strings).
    pub col: u32,
}

/// A tokenizer over one file's bytes.
#[derive(Debug)]
pub struct Lexer {
    text: Vec<u8>,
    file: Arc<Path>,
    pos: usize,
    line: u32,
    line_start: usize,
    peeked: Option<Token>,
}

impl Lexer {
    /// A lexer over `text`, reporting locations in `file`.
    pub fn new(text: Vec<u8>, file: Arc<Path>) -> Lexer {
        let bom = if text.starts_with(UTF8_BOM) {
            UTF8_BOM.len()
        } else {
            0
        };
        Lexer {
            text,
            file,
            pos: bom,
            line: 1,
            line_start: bom,
            peeked: None,
        }
    }

    /// The location of a token of this lexer.
    pub fn loc(&self, tok: &Token) -> Loc {
        Loc {
            file: self.file.clone(),
            line: tok.line,
            col: tok.col,
        }
    }

    /// The location just past the last token (for "premature end of file").
    pub fn end_loc(&self) -> Loc {
        Loc {
            file: self.file.clone(),
            line: self.line,
            col: col_of(self.pos, self.line_start),
        }
    }

    /// The raw bytes of a token (without quotes for strings).
    pub fn bytes(&self, tok: &Token) -> &[u8] {
        self.text.get(tok.start..tok.end).unwrap_or(&[])
    }

    /// The decoded text of a token; escapes are resolved for strings.
    pub fn string(&self, tok: &Token) -> Cow<'_, str> {
        let raw = self.bytes(tok);
        match tok.kind {
            TokenKind::Str { escaped: true } => Cow::Owned(unescape(raw)),
            _ => String::from_utf8_lossy(raw),
        }
    }

    /// Looks at the next token without consuming it.
    pub fn peek(&mut self) -> Result<Option<Token>, SceneError> {
        if self.peeked.is_none() {
            self.peeked = self.scan()?;
        }
        Ok(self.peeked)
    }

    /// Consumes and returns the next token, or `None` at end of file.
    pub fn next_token(&mut self) -> Result<Option<Token>, SceneError> {
        match self.peeked.take() {
            Some(t) => Ok(Some(t)),
            None => self.scan(),
        }
    }

    /// Skips whitespace and comments, then reads one token.
    fn scan(&mut self) -> Result<Option<Token>, SceneError> {
        self.skip_blank();
        let Some(&c) = self.text.get(self.pos) else {
            return Ok(None);
        };
        let start = self.pos;
        let col = col_of(start, self.line_start);
        let line = self.line;
        let kind = match c {
            b'[' => {
                self.pos += 1;
                TokenKind::Open
            }
            b']' => {
                self.pos += 1;
                TokenKind::Close
            }
            b'"' => return self.scan_string(line, col).map(Some),
            _ => {
                while let Some(&b) = self.text.get(self.pos) {
                    if is_space(b) || matches!(b, b'"' | b'[' | b']' | b'#') {
                        break;
                    }
                    self.pos += 1;
                }
                TokenKind::Word
            }
        };
        let end = self.pos;
        Ok(Some(Token {
            kind,
            start,
            end,
            line,
            col,
        }))
    }

    /// Reads a quoted string whose opening quote is at `self.pos`.
    fn scan_string(&mut self, line: u32, col: u32) -> Result<Token, SceneError> {
        let open = Loc {
            file: self.file.clone(),
            line,
            col,
        };
        self.pos += 1;
        let start = self.pos;
        let mut escaped = false;
        loop {
            match self.text.get(self.pos) {
                None | Some(b'\n') => {
                    return Err(SceneError::at(&open, "unterminated string"));
                }
                Some(b'"') => break,
                Some(b'\\') => {
                    escaped = true;
                    let esc = self.text.get(self.pos + 1).copied();
                    if !matches!(
                        esc,
                        Some(b'n' | b't' | b'r' | b'b' | b'f' | b'\\' | b'\'' | b'"')
                    ) {
                        let loc = Loc {
                            file: self.file.clone(),
                            line,
                            col: col_of(self.pos, self.line_start),
                        };
                        return Err(SceneError::at(&loc, "unknown escape sequence in string"));
                    }
                    self.pos += 2;
                }
                Some(_) => self.pos += 1,
            }
        }
        let end = self.pos;
        self.pos += 1;
        Ok(Token {
            kind: TokenKind::Str { escaped },
            start,
            end,
            line,
            col,
        })
    }

    /// Skips whitespace and `#` comments, counting lines.
    fn skip_blank(&mut self) {
        while let Some(&b) = self.text.get(self.pos) {
            if b == b'\n' {
                self.pos += 1;
                self.line = self.line.saturating_add(1);
                self.line_start = self.pos;
            } else if is_space(b) {
                self.pos += 1;
            } else if b == b'#' {
                let rest = self.text.get(self.pos..).unwrap_or(&[]);
                let n = rest.iter().position(|&c| c == b'\n').unwrap_or(rest.len());
                self.pos += n;
            } else {
                break;
            }
        }
    }
}

/// The UTF-8 encoding of U+FEFF, the byte-order mark.
const UTF8_BOM: &[u8] = b"\xef\xbb\xbf";

/// Whitespace as pbrt-v4 sees it (newline handled separately).
fn is_space(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\r' | b'\n' | 0x0b | 0x0c)
}

/// 1-based column of byte `pos` on a line starting at `line_start`.
fn col_of(pos: usize, line_start: usize) -> u32 {
    u32::try_from(pos.saturating_sub(line_start) + 1).unwrap_or(u32::MAX)
}

/// Resolves backslash escapes (already validated by the lexer).
fn unescape(raw: &[u8]) -> String {
    let mut out = Vec::with_capacity(raw.len());
    let mut it = raw.iter();
    while let Some(&b) = it.next() {
        if b != b'\\' {
            out.push(b);
            continue;
        }
        let c = match it.next() {
            Some(b'n') => b'\n',
            Some(b't') => b'\t',
            Some(b'r') => b'\r',
            Some(b'b') => 0x08,
            Some(b'f') => 0x0c,
            Some(&c) => c,
            None => break,
        };
        out.push(c);
    }
    String::from_utf8_lossy(&out).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lex(s: &str) -> (Lexer, Vec<Token>) {
        let mut l = Lexer::new(s.as_bytes().to_vec(), Arc::from(Path::new("t.pbrt")));
        let mut v = Vec::new();
        while let Some(t) = l.next_token().unwrap() {
            v.push(t);
        }
        (l, v)
    }

    #[test]
    fn tokens_and_positions() {
        let (l, t) = lex("Shape \"a\\\"b\" # c\n  [1 -2.5e1]");
        assert_eq!(t.len(), 6);
        assert_eq!(t[5].kind, TokenKind::Close);
        assert_eq!(l.bytes(&t[0]), b"Shape");
        assert_eq!(l.string(&t[1]), "a\"b");
        assert_eq!((t[1].line, t[1].col), (1, 7));
        assert_eq!(t[2].kind, TokenKind::Open);
        assert_eq!((t[2].line, t[2].col), (2, 3));
        assert_eq!(l.bytes(&t[4]), b"-2.5e1");
    }

    #[test]
    fn byte_order_mark_is_skipped() {
        let (l, t) = lex("\u{feff}LookAt 1");
        assert_eq!(l.bytes(&t[0]), b"LookAt");
        assert_eq!((t[0].line, t[0].col), (1, 1));
        assert_eq!((t[1].line, t[1].col), (1, 8));
        // Only at the start: elsewhere it is part of a word, as before.
        let (l, t) = lex("a \u{feff}b");
        assert_eq!(l.bytes(&t[1]), "\u{feff}b".as_bytes());
    }

    #[test]
    fn unterminated_string_reports_opening_quote() {
        let mut l = Lexer::new(b"a\n  \"abc\nd".to_vec(), Arc::from(Path::new("t")));
        l.next_token().unwrap();
        let e = l.next_token().unwrap_err();
        assert_eq!(e.to_string(), "t:2:3: unterminated string");
    }
}
