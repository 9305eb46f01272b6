//! pbrt-v4's typed parameter lists: `"float fov" [ 30 ]`, `"rgb reflectance" [ .5 .5 .5 ]`,
//! `"string filename" "a.ply"`, … Each parameter is read by a typed getter that checks its type and
//! value count and marks it used; what a directive never asks for is warned about.

use std::cell::Cell;

use super::tokenizer::{short, Kind, Loc, Token};

/// The declared types accepted, and what their values are.
const NUMERIC: [&str; 12] = [
    "integer",
    "float",
    "point2",
    "vector2",
    "point3",
    "vector3",
    "normal3",
    "normal",
    "point",
    "vector",
    "rgb",
    "blackbody",
];
const TEXTUAL: [&str; 2] = ["string", "texture"];

#[derive(Clone, Debug, PartialEq)]
pub enum Values {
    Numbers(Vec<f64>),
    Strings(Vec<String>),
    Bools(Vec<bool>),
}

#[derive(Debug)]
pub struct Param {
    /// The declared type, e.g. `point3` (`point` and `normal` are read as `point3` and `normal3`).
    pub ty: String,
    pub name: String,
    pub values: Values,
    /// Where the `"type name"` string is.
    pub loc: Loc,
    used: Cell<bool>,
}

#[derive(Debug, Default)]
pub struct ParamList {
    pub params: Vec<Param>,
}

/// A colour-valued parameter as written: RGB, a spectrum (as RGB), or a texture's name.
#[derive(Clone, Debug, PartialEq)]
pub enum ColourParam {
    Rgb([f64; 3]),
    Texture(String),
}

/// Reads `"type name" value` pairs from `tokens[*at..]` while the next token is a string holding
/// two words (the directive's own arguments come before).
pub fn parse(tokens: &[Token], at: &mut usize) -> Result<ParamList, String> {
    let mut list = ParamList::default();
    while let Some(Token { kind: Kind::Str(decl), loc }) = tokens.get(*at) {
        let words: Vec<&str> = decl.split_whitespace().collect();
        let [ty, name] = words[..] else {
            // A lone string after a directive's arguments is a syntax error.
            return Err(format!("{loc}: expected a parameter \"type name\", found \"{}\"", short(decl)));
        };
        let ty = match ty {
            "point" => "point3",
            "vector" => "vector3",
            "normal" => "normal3",
            "color" => "rgb",
            "bool" => "bool",
            t => t,
        };
        if !(NUMERIC.contains(&ty) || TEXTUAL.contains(&ty) || ty == "bool" || ty == "spectrum") {
            return Err(format!(
                "{loc}: unknown parameter type '{}' (supported: integer, float, point2, vector2, point3, vector3, normal3, rgb, spectrum, blackbody, bool, string, texture)",
                short(ty)
            ));
        }
        if list.params.iter().any(|p| p.name == name) {
            return Err(format!("{loc}: parameter '{}' is given twice", short(name)));
        }
        *at += 1;
        // One value, or a bracketed list.
        let mut raw: Vec<&Token> = Vec::new();
        match tokens.get(*at) {
            Some(Token { kind: Kind::Open, .. }) => {
                *at += 1;
                loop {
                    match tokens.get(*at) {
                        Some(Token { kind: Kind::Close, .. }) => {
                            *at += 1;
                            break;
                        }
                        Some(t @ Token { kind: Kind::Number(_) | Kind::Str(_) | Kind::Word(_), .. }) => {
                            raw.push(t);
                            *at += 1;
                        }
                        Some(t) => return Err(format!("{}: '[' inside a parameter's value list", t.loc)),
                        None => return Err(format!("{loc}: the value list of '{name}' is never closed (no ']')")),
                    }
                }
            }
            Some(t @ Token { kind: Kind::Number(_) | Kind::Str(_), .. }) => {
                raw.push(t);
                *at += 1;
            }
            Some(t @ Token { kind: Kind::Word(w), .. }) if w == "true" || w == "false" => {
                raw.push(t);
                *at += 1;
            }
            _ => return Err(format!("{loc}: parameter '{name}' has no value")),
        }
        let values = if ty == "bool" {
            let mut b = Vec::new();
            for t in &raw {
                match &t.kind {
                    Kind::Word(w) | Kind::Str(w) if w == "true" => b.push(true),
                    Kind::Word(w) | Kind::Str(w) if w == "false" => b.push(false),
                    _ => return Err(format!("{}: a bool is true or false", t.loc)),
                }
            }
            Values::Bools(b)
        } else if TEXTUAL.contains(&ty)
            || (ty == "spectrum" && matches!(raw.first().map(|t| &t.kind), Some(Kind::Str(_))))
        {
            let mut s = Vec::new();
            for t in &raw {
                match &t.kind {
                    Kind::Str(v) => s.push(v.clone()),
                    _ => return Err(format!("{}: '{name}' is a {ty}: its values must be quoted strings", t.loc)),
                }
            }
            Values::Strings(s)
        } else {
            let mut n = Vec::new();
            for t in &raw {
                match &t.kind {
                    Kind::Number(v) => n.push(*v),
                    _ => return Err(format!("{}: '{name}' is a {ty}: its values must be numbers", t.loc)),
                }
            }
            Values::Numbers(n)
        };
        list.params.push(Param {
            ty: ty.to_string(),
            name: name.to_string(),
            values,
            loc: loc.clone(),
            used: Cell::new(false),
        });
    }
    Ok(list)
}

fn count_word(n: usize) -> &'static str {
    match n {
        1 => "one value",
        2 => "two values",
        3 => "three values",
        _ => "values",
    }
}

impl ParamList {
    fn find(&self, name: &str) -> Option<&Param> {
        let p = self.params.iter().find(|p| p.name == name)?;
        p.used.set(true);
        Some(p)
    }

    /// The numbers of `name` if it is declared with one of `types`, their count a multiple of
    /// `group` (and exactly `group` when `one`).
    fn numbers(&self, name: &str, types: &[&str], group: usize, one: bool) -> Result<Option<&[f64]>, String> {
        let Some(p) = self.find(name) else { return Ok(None) };
        if !types.contains(&p.ty.as_str()) {
            return Err(format!(
                "{}: parameter '{name}' is declared '{}': expected '{}'",
                p.loc,
                p.ty,
                types.join("' or '")
            ));
        }
        let Values::Numbers(v) = &p.values else {
            return Err(format!("{}: parameter '{name}' must have numeric values", p.loc));
        };
        if (one && v.len() != group) || v.is_empty() || !v.len().is_multiple_of(group) {
            let want = if one { count_word(group).to_string() } else { format!("a multiple of {group} values") };
            return Err(format!("{}: '{} {name}' takes {want}, {} given", p.loc, p.ty, v.len()));
        }
        Ok(Some(v))
    }

    pub fn float(&self, name: &str, default: f64) -> Result<f64, String> {
        Ok(self.numbers(name, &["float"], 1, true)?.map_or(default, |v| v[0]))
    }

    pub fn integer(&self, name: &str, default: i64) -> Result<i64, String> {
        let Some(v) = self.numbers(name, &["integer"], 1, true)? else { return Ok(default) };
        let p = self.find(name).expect("found above");
        as_integer(v[0]).ok_or_else(|| format!("{}: '{name}' must be a whole number, not {}", p.loc, v[0]))
    }

    pub fn integers(&self, name: &str) -> Result<Option<Vec<i64>>, String> {
        let Some(v) = self.numbers(name, &["integer"], 1, false)? else { return Ok(None) };
        let p = self.find(name).expect("found above");
        v.iter()
            .map(|&x| as_integer(x).ok_or_else(|| format!("{}: '{name}' holds {x}, not a whole number", p.loc)))
            .collect::<Result<Vec<_>, _>>()
            .map(Some)
    }

    /// `point3`, `vector3` or `normal3` values, in threes.
    pub fn triples(&self, name: &str, ty: &str) -> Result<Option<Vec<[f64; 3]>>, String> {
        Ok(self.numbers(name, &[ty], 3, false)?.map(|v| v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()))
    }

    /// One `point3` (or `vector3`).
    pub fn point(&self, name: &str, ty: &str, default: [f64; 3]) -> Result<[f64; 3], String> {
        Ok(self.numbers(name, &[ty], 3, true)?.map_or(default, |v| [v[0], v[1], v[2]]))
    }

    pub fn pairs(&self, name: &str) -> Result<Option<Vec<[f64; 2]>>, String> {
        Ok(self
            .numbers(name, &["point2", "float"], 2, false)?
            .map(|v| v.chunks_exact(2).map(|c| [c[0], c[1]]).collect()))
    }

    pub fn string(&self, name: &str) -> Result<Option<String>, String> {
        let Some(p) = self.find(name) else { return Ok(None) };
        match (&p.values, p.ty.as_str()) {
            (Values::Strings(s), "string") if s.len() == 1 => Ok(Some(s[0].clone())),
            (_, "string") => Err(format!("{}: 'string {name}' takes one value", p.loc)),
            _ => Err(format!("{}: parameter '{name}' is declared '{}': expected 'string'", p.loc, p.ty)),
        }
    }

    pub fn boolean(&self, name: &str, default: bool) -> Result<bool, String> {
        let Some(p) = self.find(name) else { return Ok(default) };
        match &p.values {
            Values::Bools(b) if b.len() == 1 => Ok(b[0]),
            _ => Err(format!("{}: parameter '{name}' must be 'bool' with one value (true or false)", p.loc)),
        }
    }

    /// A colour: `rgb` (three values), `spectrum` (wavelength/value pairs, a named spectrum, or one
    /// constant value), a `float` (grey), or a `texture` name when `texture_ok`.
    pub fn colour(&self, name: &str, texture_ok: bool) -> Result<Option<ColourParam>, String> {
        let Some(p) = self.find(name) else { return Ok(None) };
        let loc = &p.loc;
        match (p.ty.as_str(), &p.values) {
            ("rgb", Values::Numbers(v)) if v.len() == 3 => Ok(Some(ColourParam::Rgb([v[0], v[1], v[2]]))),
            ("rgb", _) => Err(format!("{loc}: 'rgb {name}' takes three values")),
            ("float", Values::Numbers(v)) if v.len() == 1 => Ok(Some(ColourParam::Rgb([v[0]; 3]))),
            ("spectrum", Values::Numbers(v)) if v.len() == 1 => Ok(Some(ColourParam::Rgb([v[0]; 3]))),
            ("spectrum", Values::Numbers(v)) => spectrum_rgb(v).map(|c| Some(ColourParam::Rgb(c))).map_err(|why| format!("{loc}: 'spectrum {name}': {why}")),
            ("spectrum", Values::Strings(s)) if s.len() == 1 => named_spectrum(&s[0])
                .map(|c| Some(ColourParam::Rgb(c)))
                .ok_or_else(|| format!("{loc}: 'spectrum {name}': named spectrum \"{}\" is not supported (supported: the stdillum-* illuminants, read as white, and glass-BK7, -BAF10, -FK51A, -LASF9, -F5, -F10, -F11 as constants; or rgb, or wavelength/value pairs)", short(&s[0]))),
            ("texture", Values::Strings(s)) if texture_ok && s.len() == 1 => Ok(Some(ColourParam::Texture(s[0].clone()))),
            ("blackbody", _) => Err(format!("{loc}: 'blackbody {name}' is not supported: give the colour as 'rgb {name}'")),
            (ty, _) => Err(format!(
                "{loc}: parameter '{name}' is declared '{ty}': expected 'rgb', 'spectrum'{}",
                if texture_ok { ", 'float' or 'texture'" } else { " or 'float'" }
            )),
        }
    }

    /// Warnings for the parameters no getter asked for: `what` names the directive.
    pub fn unused(&self, what: &str) -> Vec<String> {
        self.params
            .iter()
            .filter(|p| !p.used.get())
            .map(|p| format!("{}: parameter '{} {}' of {what} is not used (ignored)", p.loc, p.ty, p.name))
            .collect()
    }
}

fn as_integer(x: f64) -> Option<i64> {
    (x.fract() == 0.0 && x.abs() < 9.0e15).then_some(x as i64)
}

/// A sampled spectrum (wavelength nm, value pairs, increasing) as RGB: its value at 610, 550 and
/// 465 nm, linearly interpolated (clamped at the ends). An approximation, documented.
fn spectrum_rgb(v: &[f64]) -> Result<[f64; 3], String> {
    if v.len() < 4 || !v.len().is_multiple_of(2) {
        return Err("wavelength/value pairs needed (at least two)".into());
    }
    let pairs: Vec<(f64, f64)> = v.chunks_exact(2).map(|c| (c[0], c[1])).collect();
    if pairs.windows(2).any(|w| w[1].0 <= w[0].0) {
        return Err("the wavelengths must increase".into());
    }
    let at = |l: f64| {
        if l <= pairs[0].0 {
            return pairs[0].1;
        }
        for w in pairs.windows(2) {
            if l <= w[1].0 {
                let t = (l - w[0].0) / (w[1].0 - w[0].0);
                return w[0].1 + t * (w[1].1 - w[0].1);
            }
        }
        pairs[pairs.len() - 1].1
    };
    Ok([at(610.0), at(550.0), at(465.0)])
}

/// The named spectra read: illuminants as white (pbrt normalises lights to their luminance), and
/// Schott glasses' index at the d line (587.6 nm) as a constant (for `eta`).
fn named_spectrum(name: &str) -> Option<[f64; 3]> {
    if name.starts_with("stdillum-") {
        return Some([1.0; 3]);
    }
    let n = match name {
        "glass-BK7" => 1.5168,
        "glass-BAF10" => 1.6700,
        "glass-FK51A" => 1.4866,
        "glass-LASF9" => 1.8503,
        "glass-F5" => 1.6034,
        "glass-F10" => 1.6200,
        "glass-F11" => 1.6209,
        _ => return None,
    };
    Some([n; 3])
}

#[cfg(test)]
mod tests {
    use super::super::tokenizer::tokenize;
    use super::*;

    fn params(text: &str) -> Result<ParamList, String> {
        let t = tokenize(text, "p").unwrap();
        let mut at = 0;
        let list = parse(&t, &mut at)?;
        assert_eq!(at, t.len());
        Ok(list)
    }

    #[test]
    fn typed_getters() {
        let p = params(r#""float fov" [ 30 ] "rgb reflectance" [ .5 .5 .5 ] "string filename" "a.ply" "point3 P" [0 0 0 1 0 0 0 1 0] "integer indices" [0 1 2] "bool x" true "spectrum s" [400 1 700 0] "point2 uv" [0 0 1 0 0 1]"#).unwrap();
        assert_eq!(p.float("fov", 90.0).unwrap(), 30.0);
        assert_eq!(p.colour("reflectance", true).unwrap(), Some(ColourParam::Rgb([0.5; 3])));
        assert_eq!(p.string("filename").unwrap().as_deref(), Some("a.ply"));
        assert_eq!(p.triples("P", "point3").unwrap().unwrap().len(), 3);
        assert_eq!(p.integers("indices").unwrap(), Some(vec![0, 1, 2]));
        assert!(p.boolean("x", false).unwrap());
        let s = match p.colour("s", false).unwrap() {
            Some(ColourParam::Rgb(c)) => c,
            other => panic!("{other:?}"),
        };
        assert!((s[1] - 0.5).abs() < 1e-12 && s[0] < s[1] && s[2] > s[1]);
        assert_eq!(p.pairs("uv").unwrap().unwrap().len(), 3);
        assert!(p.unused("Shape").is_empty());
        assert_eq!(p.float("absent", 2.0).unwrap(), 2.0);
    }

    #[test]
    fn wrong_types_and_counts_name_the_parameter() {
        let p = params(r#""integer fov" 30 "rgb c" [1 2] "point3 P" [0 0 0 1]"#).unwrap();
        assert!(p
            .float("fov", 0.0)
            .unwrap_err()
            .contains("p:1:1: parameter 'fov' is declared 'integer': expected 'float'"));
        assert!(p.colour("c", false).unwrap_err().contains("takes three values"));
        assert!(p.triples("P", "point3").unwrap_err().contains("multiple of 3"));
        assert!(params(r#""float" 1"#).unwrap_err().contains("\"type name\""));
        assert!(params(r#""quaternion q" [1]"#).unwrap_err().contains("unknown parameter type 'quaternion'"));
        assert!(params(r#""float a" [1 "#).unwrap_err().contains("never closed"));
        assert!(params(r#""float a" 1 "float a" 2"#).unwrap_err().contains("twice"));
        assert!(params(r#""float a" "x""#).unwrap_err().contains("must be numbers"));
        let unused = params(r#""float extra" 1"#).unwrap().unused("Shape \"sphere\"");
        assert_eq!(unused, vec!["p:1:1: parameter 'float extra' of Shape \"sphere\" is not used (ignored)"]);
    }
}
