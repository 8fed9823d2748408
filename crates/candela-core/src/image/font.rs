//! A tiny bitmap font for the numbers and units of false-colour legends
//! ([`super::falsecolor`]): digits, `.`, `e`, `+`, `-`, the letters of
//! `cd/m²` and `lx`, drawn on a 5-row grid, 1–5 columns wide (hand-made;
//! no font file, no dependency). Each font pixel is drawn as a
//! `scale × scale` square.

/// Rows of every glyph.
pub const ROWS: usize = 5;

/// The glyph of `c` as rows of `#` (ink) and `.` (none); `None` if the
/// font lacks it.
fn glyph(c: char) -> Option<[&'static str; ROWS]> {
    Some(match c {
        '0' => ["###", "#.#", "#.#", "#.#", "###"],
        '1' => [".#.", "##.", ".#.", ".#.", "###"],
        '2' => ["###", "..#", "###", "#..", "###"],
        '3' => ["###", "..#", ".##", "..#", "###"],
        '4' => ["#.#", "#.#", "###", "..#", "..#"],
        '5' => ["###", "#..", "###", "..#", "###"],
        '6' => ["###", "#..", "###", "#.#", "###"],
        '7' => ["###", "..#", ".#.", ".#.", ".#."],
        '8' => ["###", "#.#", "###", "#.#", "###"],
        '9' => ["###", "#.#", "###", "..#", "###"],
        '.' => [".", ".", ".", ".", "#"],
        '-' => ["...", "...", "###", "...", "..."],
        '+' => ["...", ".#.", "###", ".#.", "..."],
        'e' => ["...", ".#.", "###", "#..", ".##"],
        'c' => ["...", ".##", "#..", "#..", ".##"],
        'd' => ["..#", "..#", "###", "#.#", "###"],
        'm' => [".....", "####.", "#.#.#", "#.#.#", "#.#.#"],
        'l' => ["#.", "#.", "#.", "#.", ".#"],
        'x' => ["...", "#.#", ".#.", ".#.", "#.#"],
        '/' => ["..#", "..#", ".#.", "#..", "#.."],
        '²' => ["##", ".#", "#.", "##", ".."],
        ' ' => ["..", "..", "..", "..", ".."],
        _ => return None,
    })
}

/// Width in font pixels of `c` (0 if the font lacks it).
fn glyph_width(c: char) -> usize {
    glyph(c).map_or(0, |g| g[0].len())
}

/// Width in image pixels of `text` at `scale` (one font pixel between glyphs).
pub fn text_width(text: &str, scale: usize) -> usize {
    let cols: usize = text.chars().map(|c| glyph_width(c) + 1).sum();
    cols.saturating_sub(1) * scale
}

/// Height in image pixels of a line at `scale`.
pub fn text_height(scale: usize) -> usize {
    ROWS * scale
}

/// True when every character of `text` has a glyph.
pub fn can_draw(text: &str) -> bool {
    text.chars().all(|c| glyph(c).is_some())
}

/// Calls `ink(x, y)` for every image pixel of `text` drawn with its top-left
/// corner at (x0, y0); characters without a glyph are skipped.
pub fn draw(text: &str, x0: usize, y0: usize, scale: usize, ink: &mut dyn FnMut(usize, usize)) {
    let mut x = x0;
    for c in text.chars() {
        let Some(g) = glyph(c) else { continue };
        for (r, row) in g.iter().enumerate() {
            for (k, b) in row.bytes().enumerate() {
                if b != b'#' {
                    continue;
                }
                for dy in 0..scale {
                    for dx in 0..scale {
                        ink(x + k * scale + dx, y0 + r * scale + dy);
                    }
                }
            }
        }
        x += (g[0].len() + 1) * scale;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CHARS: &str = "0123456789.-+ecdmlx/² ";

    #[test]
    fn glyphs_are_rectangular_and_distinct() {
        let mut seen = Vec::new();
        for c in CHARS.chars() {
            let g = glyph(c).expect("glyph");
            assert!(g.iter().all(|r| r.len() == g[0].len()), "{c:?} ragged");
            assert!(
                g.iter().all(|r| r.bytes().all(|b| b == b'#' || b == b'.')),
                "{c:?}"
            );
            assert!(!seen.contains(&g), "{c:?} looks like another glyph");
            seen.push(g);
        }
        assert!(glyph('Q').is_none() && !can_draw("1Q") && can_draw("cd/m²"));
    }

    #[test]
    fn drawn_text_has_its_width_and_ink() {
        let text = "1.5e+03 lx";
        let scale = 2;
        let (mut max_x, mut max_y, mut n) = (0, 0, 0);
        draw(text, 3, 4, scale, &mut |x, y| {
            max_x = max_x.max(x);
            max_y = max_y.max(y);
            n += 1;
        });
        assert!(max_x < 3 + text_width(text, scale));
        assert_eq!(max_y, 4 + text_height(scale) - 1);
        let ink: usize = text
            .chars()
            .map(|c| {
                glyph(c)
                    .unwrap()
                    .iter()
                    .map(|r| r.matches('#').count())
                    .sum::<usize>()
            })
            .sum();
        assert_eq!(n, ink * scale * scale);
        assert_eq!(text_width("8", 3), 9);
        assert_eq!(text_width("", 3), 0);
    }
}
