//! The directive loop: tokens from a stack of files -> [`Builder`] calls.
//!
//! The parser reads the main file and any `Include`d/`Import`ed files as a
//! stack of [`Lexer`]s. A directive and all its arguments must come from one
//! file; only the search for the next directive moves down the stack when an
//! included file ends. Relative include paths resolve against the main
//! file's directory (pbrt-v4's search directory). Nesting deeper than
//! [`MAX_INCLUDE_DEPTH`] or including a file that is already open is an
//! error rather than a stack overflow. Files ending in `.gz` are gunzipped.
//!
//! Including a file that is not open is allowed any number of times, so a
//! few small files that each include the next one ten times would expand
//! exponentially (a "billion laughs"). The parser therefore stops after
//! [`MAX_INCLUDED_FILES`] `Include`/`Import` directives in one scene; real
//! scenes use thousands at most. Each file is read through `input`, which
//! refuses devices, FIFOs and directories and bounds the size.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::builder::{Block, Builder, OptionEntity};
use crate::desc::SceneDescription;
use crate::error::{Loc, SceneError};
use crate::input;
use crate::lexer::{Lexer, Token, TokenKind};
use crate::math::Mat4d;
use crate::param::{resolve_path, ParamSet};
use crate::paramlist::{describe, parse_param};

type Result<T> = std::result::Result<T, SceneError>;

/// Maximum number of files open at once through `Include`/`Import`.
pub const MAX_INCLUDE_DEPTH: usize = 32;

/// Maximum number of `Include`/`Import` directives followed in one scene.
pub const MAX_INCLUDED_FILES: usize = 100_000;

/// One open file.
struct Source {
    lexer: Lexer,
    /// Canonical path, for include-cycle detection.
    key: PathBuf,
    /// Whether the file was `Import`ed (its graphics state is scoped).
    import: bool,
}

/// Parser state: the file stack and the builder.
struct Parser {
    files: Vec<Source>,
    base_dir: Arc<Path>,
    b: Builder,
    end: Loc,
    /// `Include`/`Import` directives followed so far.
    included: usize,
}

/// Reads a scene file, gunzipping `.gz` files; errors are reported at `loc`.
pub(crate) fn read_scene_file(path: &Path, loc: &Loc) -> Result<Vec<u8>> {
    input::read_file(path, loc, input::MAX_SCENE_FILE_BYTES)
}

/// Parses scene `text` that claims to live at `path`.
pub(crate) fn parse_bytes(text: Vec<u8>, path: &Path) -> Result<SceneDescription> {
    let base_dir: Arc<Path> = Arc::from(path.parent().unwrap_or(Path::new("")));
    let file: Arc<Path> = Arc::from(path);
    let mut b = Builder::new(&base_dir);
    b.add_source(path, &text);
    let lexer = Lexer::new(text, file);
    let mut p = Parser {
        files: vec![Source {
            lexer,
            key: canonical(path),
            import: false,
        }],
        b,
        base_dir,
        end: Loc::file_only(path),
        included: 0,
    };
    p.run()?;
    let end = p.end.clone();
    p.b.finish(&end)
}

/// The canonical form of `path` if it exists, else `path` itself.
fn canonical(path: &Path) -> PathBuf {
    std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf())
}

impl Parser {
    /// The innermost open file.
    fn lx(&mut self) -> Result<&mut Lexer> {
        match self.files.last_mut() {
            Some(s) => Ok(&mut s.lexer),
            None => Err(SceneError::at(&self.end, "premature end of input")),
        }
    }

    /// The next directive token, popping finished files.
    fn next_directive(&mut self) -> Result<Option<(Token, Loc)>> {
        while let Some(src) = self.files.last_mut() {
            if let Some(t) = src.lexer.next_token()? {
                let loc = src.lexer.loc(&t);
                return Ok(Some((t, loc)));
            }
            self.end = src.lexer.end_loc();
            let import = src.import;
            self.files.pop();
            if import {
                let end = self.end.clone();
                self.b.pop(Block::Import, "end of imported file", &end)?;
            }
        }
        Ok(None)
    }

    /// Reads every directive.
    fn run(&mut self) -> Result<()> {
        while let Some((tok, loc)) = self.next_directive()? {
            let lx = self.lx()?;
            if tok.kind != TokenKind::Word {
                let what = describe(lx, &tok);
                return Err(SceneError::at(
                    &loc,
                    format!("expected a directive, found {what}"),
                ));
            }
            let name = lx.bytes(&tok).to_vec();
            if !self.simple_directive(&name, &loc)? {
                let name = String::from_utf8_lossy(&name).into_owned();
                if !self.entity_directive(&name, &loc)? {
                    return Err(SceneError::at(&loc, format!("unknown directive '{name}'")));
                }
            }
        }
        Ok(())
    }

    /// Directives without parameter lists. Returns false if `name` is not one.
    fn simple_directive(&mut self, name: &[u8], loc: &Loc) -> Result<bool> {
        let b = &mut self.b;
        match name {
            b"Identity" => b.apply(|_| Mat4d::IDENTITY),
            b"AttributeBegin" => b.push(Block::Attribute, loc)?,
            b"AttributeEnd" => b.pop(Block::Attribute, "AttributeEnd", loc)?,
            b"TransformBegin" => b.transform_begin(loc)?,
            b"TransformEnd" => b.pop(Block::Attribute, "TransformEnd", loc)?,
            b"ReverseOrientation" => b.reverse_orientation(),
            b"WorldBegin" => b.world_begin(loc)?,
            b"WorldEnd" => b.world_end(loc),
            b"ObjectEnd" => b.object_end(loc)?,
            b"Translate" => {
                let [x, y, z] = self.numbers("Translate")?;
                self.b.apply(|m| *m * Mat4d::translate([x, y, z]));
            }
            b"Scale" => {
                let [x, y, z] = self.numbers("Scale")?;
                self.b.apply(|m| *m * Mat4d::scale([x, y, z]));
            }
            b"Rotate" => {
                let [a, x, y, z] = self.numbers("Rotate")?;
                if x == 0.0 && y == 0.0 && z == 0.0 {
                    return Err(SceneError::at(
                        loc,
                        "Rotate: the axis (0, 0, 0) has no direction",
                    ));
                }
                self.b.apply(|m| *m * Mat4d::rotate(a, [x, y, z]));
            }
            b"LookAt" => self.look_at(loc)?,
            b"Transform" => {
                let t = self.matrix("Transform")?;
                self.b.apply(|_| t);
            }
            b"ConcatTransform" => {
                let t = self.matrix("ConcatTransform")?;
                self.b.apply(|m| *m * t);
            }
            b"TransformTimes" => {
                let [s, e] = self.numbers("TransformTimes")?;
                self.b.transform_times(s as f32, e as f32, loc)?;
            }
            b"ActiveTransform" => self.active_transform()?,
            _ => return Ok(false),
        }
        Ok(true)
    }

    /// Directives taking names and/or parameter lists. False if unknown.
    fn entity_directive(&mut self, name: &str, loc: &Loc) -> Result<bool> {
        let option = |e| Some(e);
        let which = match name {
            "Film" => option(OptionEntity::Film),
            "Sampler" => option(OptionEntity::Sampler),
            "Integrator" => option(OptionEntity::Integrator),
            "PixelFilter" => option(OptionEntity::PixelFilter),
            "Accelerator" => option(OptionEntity::Accelerator),
            _ => None,
        };
        if let Some(which) = which {
            let (n, params) = self.named_params(name)?;
            self.b.option_entity(which, n, params, loc)?;
            return Ok(true);
        }
        match name {
            "Camera" => {
                let (n, p) = self.named_params(name)?;
                self.b.camera(n, p, loc)?;
            }
            "Shape" => {
                let (n, p) = self.named_params(name)?;
                self.b.shape(n, p, loc)?;
            }
            "Material" => {
                let (n, p) = self.named_params(name)?;
                self.b.material(n, p, loc)?;
            }
            "MakeNamedMaterial" => {
                let (n, p) = self.named_params(name)?;
                self.b.make_named_material(n, p, loc)?;
            }
            "LightSource" => {
                let (n, p) = self.named_params(name)?;
                self.b.light_source(n, p, loc)?;
            }
            "AreaLightSource" => {
                let (n, p) = self.named_params(name)?;
                self.b.area_light_source(n, p, loc)?;
            }
            "Attribute" => {
                let (n, p) = self.named_params(name)?;
                self.b.attribute(&n, p, loc)?;
            }
            "MakeNamedMedium" => self.b.make_named_medium(loc)?,
            _ => return self.string_directive(name, loc),
        }
        Ok(true)
    }

    /// Directives whose arguments are strings only. False if unknown.
    fn string_directive(&mut self, name: &str, loc: &Loc) -> Result<bool> {
        match name {
            "Texture" => {
                let tex = self.string_arg("Texture")?;
                let kind = self.string_arg("Texture")?;
                let (class, params) = self.named_params("Texture")?;
                self.b.texture(tex, &kind, class, params, loc)?;
            }
            "NamedMaterial" => {
                let n = self.string_arg(name)?;
                self.b.named_material(n, loc)?;
            }
            "CoordinateSystem" => {
                let n = self.string_arg(name)?;
                self.b.coordinate_system(n);
            }
            "CoordSysTransform" => {
                let n = self.string_arg(name)?;
                self.b.coord_sys_transform(&n, loc);
            }
            "ColorSpace" => {
                let n = self.string_arg(name)?;
                self.b.color_space(n);
            }
            "ObjectBegin" => {
                let n = self.string_arg(name)?;
                self.b.object_begin(n, loc)?;
            }
            "ObjectInstance" => {
                let n = self.string_arg(name)?;
                self.b.object_instance(n, loc)?;
            }
            "MediumInterface" => self.medium_interface(loc)?,
            "Option" => self.option()?,
            "Include" => self.include(loc, false)?,
            "Import" => self.include(loc, true)?,
            _ => return Ok(false),
        }
        Ok(true)
    }
}

/// Argument readers. All stay within the current file.
impl Parser {
    /// The next token of the current file, or a "premature end" error.
    fn token(&mut self, what: &str) -> Result<Token> {
        let lx = self.lx()?;
        match lx.next_token()? {
            Some(t) => Ok(t),
            None => Err(SceneError::at(
                &lx.end_loc(),
                format!("premature end of file: expected {what}"),
            )),
        }
    }

    /// `N` numbers (arguments of `directive`).
    fn numbers<const N: usize>(&mut self, directive: &str) -> Result<[f64; N]> {
        let mut out = [0.0; N];
        for v in out.iter_mut() {
            let t = self.token(&format!("a number for {directive}"))?;
            let lx = self.lx()?;
            let parsed = std::str::from_utf8(lx.bytes(&t))
                .ok()
                .and_then(|s| s.parse().ok());
            match (t.kind, parsed) {
                (TokenKind::Word, Some(x)) if !f64::is_finite(x) => {
                    let msg = format!("{directive}: {x} is not a finite number");
                    return Err(SceneError::at(&lx.loc(&t), msg));
                }
                (TokenKind::Word, Some(x)) => *v = x,
                _ => {
                    let msg = format!(
                        "expected {N} numbers for {directive}, found {}",
                        describe(lx, &t)
                    );
                    return Err(SceneError::at(&lx.loc(&t), msg));
                }
            }
        }
        Ok(out)
    }

    /// Expects a token of `kind` (a bracket).
    fn bracket(&mut self, kind: TokenKind, directive: &str) -> Result<()> {
        let c = if kind == TokenKind::Open { '[' } else { ']' };
        let t = self.token(&format!("'{c}' for {directive}"))?;
        if t.kind == kind {
            return Ok(());
        }
        let lx = self.lx()?;
        let msg = format!("expected '{c}' for {directive}, found {}", describe(lx, &t));
        Err(SceneError::at(&lx.loc(&t), msg))
    }

    /// `[ 16 numbers ]` in pbrt's column-major order, as a row-major matrix.
    fn matrix(&mut self, directive: &str) -> Result<Mat4d> {
        self.bracket(TokenKind::Open, directive)?;
        let v: [f64; 16] = self.numbers(directive)?;
        self.bracket(TokenKind::Close, directive)?;
        let mut m = Mat4d::IDENTITY;
        for (i, x) in v.iter().enumerate() {
            m.m[i % 4][i / 4] = *x;
        }
        Ok(m)
    }

    /// `LookAt ex ey ez lx ly lz ux uy uz`.
    fn look_at(&mut self, loc: &Loc) -> Result<()> {
        let v: [f64; 9] = self.numbers("LookAt")?;
        let Some(l) = Mat4d::look_at([v[0], v[1], v[2]], [v[3], v[4], v[5]], [v[6], v[7], v[8]])
        else {
            return Err(SceneError::at(
                loc,
                "LookAt: the eye and look-at points coincide or the up vector is parallel to the view direction",
            ));
        };
        self.b.apply(|m| *m * l);
        Ok(())
    }

    /// `ActiveTransform StartTime|EndTime|All`.
    fn active_transform(&mut self) -> Result<()> {
        let t = self.token("StartTime, EndTime or All")?;
        let lx = self.lx()?;
        let (s, e) = match (t.kind, lx.bytes(&t)) {
            (TokenKind::Word, b"StartTime") => (true, false),
            (TokenKind::Word, b"EndTime") => (false, true),
            (TokenKind::Word, b"All") => (true, true),
            _ => {
                let msg = format!(
                    "expected StartTime, EndTime or All after ActiveTransform, found {}",
                    describe(lx, &t)
                );
                return Err(SceneError::at(&lx.loc(&t), msg));
            }
        };
        self.b.active_transform(s, e);
        Ok(())
    }

    /// A quoted string argument of `directive`.
    fn string_arg(&mut self, directive: &str) -> Result<String> {
        let t = self.token(&format!("a quoted string for {directive}"))?;
        let lx = self.lx()?;
        if let TokenKind::Str { .. } = t.kind {
            return Ok(lx.string(&t).into_owned());
        }
        let msg = format!(
            "expected a quoted string for {directive}, found {}",
            describe(lx, &t)
        );
        Err(SceneError::at(&lx.loc(&t), msg))
    }

    /// A quoted name followed by a parameter list.
    fn named_params(&mut self, directive: &str) -> Result<(String, ParamSet)> {
        let name = self.string_arg(directive)?;
        Ok((name, self.params()?))
    }

    /// Parameters while the next token is a quoted string.
    fn params(&mut self) -> Result<ParamSet> {
        let base = self.base_dir.clone();
        let mut set = ParamSet::new(base.clone());
        let lx = self.lx()?;
        while let Some(
            t @ Token {
                kind: TokenKind::Str { .. },
                ..
            },
        ) = lx.peek()?
        {
            lx.next_token()?;
            set.params.push(parse_param(lx, &t, &base)?);
        }
        Ok(set)
    }

    /// `MediumInterface "inside" ["outside"]`.
    fn medium_interface(&mut self, loc: &Loc) -> Result<()> {
        let inside = self.string_arg("MediumInterface")?;
        let lx = self.lx()?;
        let outside = match lx.peek()? {
            Some(
                t @ Token {
                    kind: TokenKind::Str { .. },
                    ..
                },
            ) => {
                lx.next_token()?;
                lx.string(&t).into_owned()
            }
            _ => inside.clone(),
        };
        self.b.medium_interface(&inside, &outside, loc)
    }

    /// `Option "type name" value`.
    fn option(&mut self) -> Result<()> {
        let t = self.token("a quoted \"type name\" for Option")?;
        let base = self.base_dir.clone();
        let lx = self.lx()?;
        if !matches!(t.kind, TokenKind::Str { .. }) {
            let msg = format!(
                "expected a quoted \"type name\" for Option, found {}",
                describe(lx, &t)
            );
            return Err(SceneError::at(&lx.loc(&t), msg));
        }
        let p = parse_param(lx, &t, &base)?;
        self.b.option(p);
        Ok(())
    }

    /// `Include "file"` / `Import "file"`: pushes the file on the stack.
    fn include(&mut self, loc: &Loc, import: bool) -> Result<()> {
        let directive = if import { "Import" } else { "Include" };
        let name = self.string_arg(directive)?;
        if import {
            self.b.require_world("Import", loc)?;
        }
        let path = resolve_path(&self.base_dir, &name);
        if self.files.len() >= MAX_INCLUDE_DEPTH {
            return Err(SceneError::at(
                loc,
                format!("{directive} nesting deeper than {MAX_INCLUDE_DEPTH} files"),
            ));
        }
        if self.included >= MAX_INCLUDED_FILES {
            return Err(SceneError::at(
                loc,
                format!("more than {MAX_INCLUDED_FILES} Include/Import directives in one scene"),
            ));
        }
        self.included += 1;
        let key = canonical(&path);
        if self.files.iter().any(|f| f.key == key) {
            return Err(SceneError::at(
                loc,
                format!(
                    "{directive} cycle: '{}' is already being read",
                    path.display()
                ),
            ));
        }
        let text = read_scene_file(&path, loc)?;
        self.b.add_source(&path, &text);
        if import {
            self.b.push(Block::Import, loc)?;
        }
        self.files.push(Source {
            lexer: Lexer::new(text, Arc::from(path.as_path())),
            key,
            import,
        });
        Ok(())
    }
}
