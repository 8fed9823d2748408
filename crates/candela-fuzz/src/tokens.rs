//! Splitting scene text into pieces that mutations can move around.
//!
//! Scene text is cut into spans that concatenate back to the original
//! exactly: whitespace, `#` comments, quoted strings, brackets and words
//! (pbrt-v4's token classes). Mutations edit the list of pieces and join
//! it again, so untouched text stays byte for byte as it was. A
//! *directive* is a word starting with an ASCII capital letter together
//! with every piece up to the next such word.

/// The class of a piece.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Whitespace.
    Space,
    /// A `#` comment up to the end of its line.
    Comment,
    /// A quoted string including its quotes.
    Str,
    /// `[` or `]`.
    Bracket,
    /// A directive name, number or bare word.
    Word,
}

/// One piece of text.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Piece {
    /// Its class.
    pub kind: Kind,
    /// Its bytes.
    pub bytes: Vec<u8>,
}

impl Piece {
    /// A piece of `kind` holding `bytes`.
    pub fn new(kind: Kind, bytes: &[u8]) -> Piece {
        Piece {
            kind,
            bytes: bytes.to_vec(),
        }
    }

    /// Whether this piece is a token (not whitespace or a comment).
    pub fn is_token(&self) -> bool {
        !matches!(self.kind, Kind::Space | Kind::Comment)
    }

    /// Whether this piece starts a directive.
    pub fn is_directive(&self) -> bool {
        self.kind == Kind::Word && self.bytes.first().is_some_and(u8::is_ascii_uppercase)
    }

    /// Whether this piece is a number.
    pub fn is_number(&self) -> bool {
        self.kind == Kind::Word
            && std::str::from_utf8(&self.bytes).is_ok_and(|s| s.parse::<f64>().is_ok())
    }
}

/// Cuts `text` into pieces; `join(&split(t)) == t` for every `t`.
pub fn split(text: &[u8]) -> Vec<Piece> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < text.len() {
        let c = text[i];
        let (kind, end) = if c.is_ascii_whitespace() {
            (Kind::Space, run(text, i, |b| b.is_ascii_whitespace()))
        } else if c == b'#' {
            (Kind::Comment, run(text, i, |b| b != b'\n'))
        } else if c == b'"' {
            (Kind::Str, string_end(text, i))
        } else if c == b'[' || c == b']' {
            (Kind::Bracket, i + 1)
        } else {
            let word = |b: u8| !b.is_ascii_whitespace() && !matches!(b, b'"' | b'[' | b']' | b'#');
            (Kind::Word, run(text, i, word))
        };
        out.push(Piece::new(kind, &text[i..end]));
        i = end;
    }
    out
}

/// The end of the run of bytes satisfying `f` that starts at `i`.
fn run(text: &[u8], i: usize, f: impl Fn(u8) -> bool) -> usize {
    let n = text[i..]
        .iter()
        .position(|&b| !f(b))
        .unwrap_or(text.len() - i);
    i + n.max(1)
}

/// One past the closing quote of the string opening at `i` (or the end of
/// the line for an unterminated one).
fn string_end(text: &[u8], i: usize) -> usize {
    let mut j = i + 1;
    while j < text.len() {
        match text[j] {
            b'\\' => j += 2,
            b'"' => return j + 1,
            b'\n' => return j,
            _ => j += 1,
        }
    }
    text.len()
}

/// Joins pieces back into text.
pub fn join(pieces: &[Piece]) -> Vec<u8> {
    pieces
        .iter()
        .flat_map(|p| p.bytes.iter().copied())
        .collect()
}

/// Index ranges `start..end` of the directives in `pieces`.
pub fn directives(pieces: &[Piece]) -> Vec<std::ops::Range<usize>> {
    let starts: Vec<usize> = (0..pieces.len())
        .filter(|&i| pieces[i].is_directive())
        .collect();
    let mut out = Vec::with_capacity(starts.len());
    for (k, &s) in starts.iter().enumerate() {
        let end = starts.get(k + 1).copied().unwrap_or(pieces.len());
        out.push(s..end);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_round_trips_and_classifies() {
        let t = b"Shape \"sphere\" # r\n  \"float radius\" [1e3]\nWorldBegin\"x\\\"y";
        let p = split(t);
        assert_eq!(join(&p), t.to_vec());
        let kinds: Vec<Kind> = p.iter().filter(|p| p.is_token()).map(|p| p.kind).collect();
        use Kind::*;
        assert_eq!(kinds, [Word, Str, Str, Bracket, Word, Bracket, Word, Str]);
        assert_eq!(directives(&p).len(), 2);
        assert!(p.iter().any(Piece::is_number));
    }

    #[test]
    fn split_round_trips_arbitrary_bytes() {
        let mut r = crate::rng::Rng::for_case(3, 0);
        for _ in 0..200 {
            let t: Vec<u8> = (0..r.below(64)).map(|_| r.next_u64() as u8).collect();
            assert_eq!(join(&split(&t)), t);
        }
    }
}
