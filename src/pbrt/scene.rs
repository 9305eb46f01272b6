//! The directives of a pbrt-v4 scene file, read into a [`PbrtScene`]: the transformation and
//! graphics-state stacks, named materials, textures and coordinate systems, `Include`/`Import`.

use std::collections::HashMap;
use std::path::Path;

use glam::{DMat4, DVec3, Vec2, Vec3};

use super::params::{self, ColourParam, ParamList};
use super::tokenizer::{self, short, Kind, Loc, Token};
use super::{
    from_reflectance, pbrt_medium, CameraDesc, FilmDesc, LightDesc, MaterialDesc, Object, PbrtScene, Reflectance,
    Subsurface, SubsurfaceSource,
};

/// How deep `Include`/`Import` may nest, and `AttributeBegin` (with `TransformBegin`).
pub const MAX_INCLUDE_DEPTH: usize = 16;
pub const MAX_NESTING: usize = 256;
/// The largest scene file (each include counted alone) and the most tokens over all of them.
pub const MAX_SCENE_BYTES: u64 = 64 << 20;
pub const MAX_TOKENS: usize = 1 << 23;

const SUPPORTED: &str = "LookAt, Camera, Film, Scale, Translate, Rotate, Transform, ConcatTransform, Identity, \
CoordinateSystem, CoordSysTransform, ReverseOrientation, AttributeBegin/End, TransformBegin/End, WorldBegin, \
MakeNamedMaterial, NamedMaterial, Material, Texture, Shape, LightSource, Include, Import; Sampler, PixelFilter, \
Integrator, ColorSpace, Option and Accelerator are ignored";

#[derive(Clone)]
struct GraphicsState {
    ctm: DMat4,
    reverse_orientation: bool,
    material: MaterialDesc,
}

enum Texture {
    Colour(Reflectance),
}

struct Parser {
    scene: PbrtScene,
    state: GraphicsState,
    stack: Vec<(GraphicsState, Loc)>,
    named_materials: HashMap<String, MaterialDesc>,
    textures: HashMap<String, Texture>,
    coordinate_systems: HashMap<String, DMat4>,
    /// The last `LookAt`'s eye, point looked at and up, with the CTM it left: a camera declared
    /// under that CTM takes them as written (the same numbers as `--eye/--target/--up`).
    look_at: Option<(DMat4, DVec3, DVec3, DVec3)>,
    tokens_read: usize,
    in_world: bool,
    warned: Vec<String>,
}

fn err(loc: &Loc, why: impl std::fmt::Display) -> String {
    format!("{loc}: {why}")
}

/// Reads a file with the same checks as a mesh: a regular file, at most [`MAX_SCENE_BYTES`], UTF-8.
fn read_text(path: &Path, from: Option<&Loc>) -> Result<String, String> {
    use std::io::Read;
    let shown = path.display();
    let at = from.map(|l| format!("{l}: ")).unwrap_or_default();
    let meta = std::fs::metadata(path).map_err(|e| format!("{at}cannot read {shown}: {e}"))?;
    if !meta.is_file() {
        return Err(format!("{at}{shown}: not a regular file (a folder, FIFO or device cannot be a scene)"));
    }
    if meta.len() > MAX_SCENE_BYTES {
        return Err(format!("{at}{shown}: larger than the limit of {} MiB for a scene file", MAX_SCENE_BYTES >> 20));
    }
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(MAX_SCENE_BYTES + 1).read_to_end(&mut bytes))
        .map_err(|e| format!("{at}cannot read {shown}: {e}"))?;
    if bytes.len() as u64 > MAX_SCENE_BYTES {
        return Err(format!("{at}{shown}: larger than the limit of {} MiB for a scene file", MAX_SCENE_BYTES >> 20));
    }
    let text = String::from_utf8(bytes)
        .map_err(|e| format!("{at}{shown}: not UTF-8 text (byte {} is invalid)", e.utf8_error().valid_up_to() + 1))?;
    Ok(text.strip_prefix('\u{feff}').map(str::to_string).unwrap_or(text))
}

pub fn load(path: &Path) -> Result<PbrtScene, String> {
    let mut p = Parser {
        scene: PbrtScene::default(),
        state: GraphicsState { ctm: DMat4::IDENTITY, reverse_orientation: false, material: MaterialDesc::default() },
        stack: Vec::new(),
        named_materials: HashMap::new(),
        textures: HashMap::new(),
        coordinate_systems: HashMap::new(),
        look_at: None,
        tokens_read: 0,
        in_world: false,
        warned: Vec::new(),
    };
    p.file(path, None, 0)?;
    if let Some((_, loc)) = p.stack.last() {
        return Err(err(loc, "AttributeBegin without AttributeEnd"));
    }
    Ok(p.scene)
}

impl Parser {
    fn warn(&mut self, w: String) {
        self.scene.warnings.push(w);
    }

    fn file(&mut self, path: &Path, from: Option<&Loc>, depth: usize) -> Result<(), String> {
        if depth > MAX_INCLUDE_DEPTH {
            return Err(err(
                from.expect("an include"),
                format!("Include nested deeper than {MAX_INCLUDE_DEPTH} files (a cycle?)"),
            ));
        }
        let text = read_text(path, from)?;
        let tokens = tokenizer::tokenize(&text, &path.display().to_string())?;
        self.tokens_read += tokens.len();
        if self.tokens_read > MAX_TOKENS {
            return Err(format!("{}: more than {MAX_TOKENS} tokens in the scene (its files together)", path.display()));
        }
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        let mut at = 0;
        while at < tokens.len() {
            let t = &tokens[at];
            let Kind::Word(directive) = &t.kind else {
                return Err(err(&t.loc, format!("expected a directive, found {}", describe(&t.kind))));
            };
            at += 1;
            self.directive(directive, &t.loc, &tokens, &mut at, &dir, depth)?;
        }
        Ok(())
    }

    fn directive(
        &mut self,
        name: &str,
        loc: &Loc,
        t: &[Token],
        at: &mut usize,
        dir: &Path,
        depth: usize,
    ) -> Result<(), String> {
        let ctm = self.state.ctm;
        match name {
            "Identity" => self.state.ctm = DMat4::IDENTITY,
            "Translate" => {
                let v = numbers(t, at, 3, loc, name)?;
                self.state.ctm = ctm * DMat4::from_translation(DVec3::new(v[0], v[1], v[2]));
            }
            "Scale" => {
                let v = numbers(t, at, 3, loc, name)?;
                self.state.ctm = ctm * DMat4::from_scale(DVec3::new(v[0], v[1], v[2]));
            }
            "Rotate" => {
                let v = numbers(t, at, 4, loc, name)?;
                let axis = DVec3::new(v[1], v[2], v[3]);
                let axis = axis.try_normalize().ok_or_else(|| err(loc, "Rotate: the axis must be non-zero"))?;
                self.state.ctm = ctm * DMat4::from_axis_angle(axis, v[0].to_radians());
            }
            "LookAt" => {
                let v = numbers(t, at, 9, loc, name)?;
                let (eye, look, up) =
                    (DVec3::new(v[0], v[1], v[2]), DVec3::new(v[3], v[4], v[5]), DVec3::new(v[6], v[7], v[8]));
                let dir = (look - eye)
                    .try_normalize()
                    .ok_or_else(|| err(loc, "LookAt: the eye and the point looked at are the same"))?;
                let right = up
                    .try_normalize()
                    .map(|u| u.cross(dir))
                    .and_then(|r| r.try_normalize())
                    .ok_or_else(|| err(loc, "LookAt: 'up' is zero or parallel to the viewing direction"))?;
                let new_up = dir.cross(right);
                // pbrt's camera space: x = up × dir (right in the image), y up, z forward.
                let world_from_camera =
                    DMat4::from_cols(right.extend(0.0), new_up.extend(0.0), dir.extend(0.0), eye.extend(1.0));
                self.state.ctm = ctm * world_from_camera.inverse();
                self.look_at = Some((self.state.ctm, eye, look, up));
            }
            "Transform" | "ConcatTransform" => {
                let v = bracketed(t, at, 16, loc, name)?;
                // pbrt's matrices are written column by column (its Transform transposes the rows).
                let m = DMat4::from_cols_array(&v.try_into().expect("16 values"));
                if m.determinant().abs() < 1e-300 || !m.is_finite() {
                    return Err(err(loc, format!("{name}: the matrix is singular or not finite")));
                }
                self.state.ctm = if name == "Transform" { m } else { ctm * m };
            }
            "CoordinateSystem" => {
                let n = string_arg(t, at, loc, name)?;
                self.coordinate_systems.insert(n, ctm);
            }
            "CoordSysTransform" => {
                let n = string_arg(t, at, loc, name)?;
                self.state.ctm = *self.coordinate_systems.get(&n).ok_or_else(|| {
                    err(loc, format!("CoordSysTransform: no coordinate system named \"{}\" (CoordinateSystem defines them; \"camera\" and \"world\" exist after Camera and WorldBegin)", short(&n)))
                })?;
            }
            "ReverseOrientation" => self.state.reverse_orientation = !self.state.reverse_orientation,
            "AttributeBegin" | "TransformBegin" => {
                if self.stack.len() >= MAX_NESTING {
                    return Err(err(loc, format!("{name} nested deeper than {MAX_NESTING}")));
                }
                if name == "TransformBegin" {
                    self.warn(err(
                        loc,
                        "TransformBegin is deprecated in pbrt-v4 (read as AttributeBegin for the transformation)",
                    ));
                }
                self.stack.push((self.state.clone(), loc.clone()));
            }
            "AttributeEnd" | "TransformEnd" => {
                let (saved, _) =
                    self.stack.pop().ok_or_else(|| err(loc, format!("{name} without a matching begin")))?;
                if name == "TransformEnd" {
                    self.state.ctm = saved.ctm;
                } else {
                    self.state = saved;
                }
            }
            "WorldBegin" => {
                if self.in_world {
                    return Err(err(loc, "a second WorldBegin"));
                }
                self.in_world = true;
                self.state.ctm = DMat4::IDENTITY;
                self.coordinate_systems.insert("world".into(), DMat4::IDENTITY);
            }
            "Camera" => {
                let kind = string_arg(t, at, loc, name)?;
                let p = params::parse(t, at)?;
                if kind != "perspective" {
                    return Err(err(
                        loc,
                        format!("Camera \"{}\" is not supported: only \"perspective\"", short(&kind)),
                    ));
                }
                let fov = p.float("fov", 90.0)?;
                if !(fov > 0.0 && fov < 180.0) {
                    return Err(err(loc, format!("Camera: fov {fov} must be within (0, 180) degrees")));
                }
                let world_from_camera = ctm.inverse();
                if !world_from_camera.is_finite() {
                    return Err(err(loc, "Camera: the transformation is singular"));
                }
                let eye = world_from_camera.transform_point3(DVec3::ZERO);
                let forward = world_from_camera.transform_vector3(DVec3::Z);
                let up = world_from_camera.transform_vector3(DVec3::Y);
                let right = world_from_camera.transform_vector3(DVec3::X);
                // pbrt's camera space is left-handed (x right, y up, z forward): a right-handed
                // camera sees the mirror image unless the transformation flips it (Scale -1 1 1).
                let left_handed = right.dot(up.cross(forward)) > 0.0;
                let (eye, target, up) = match self.look_at {
                    Some((m, e, look, u)) if m == ctm => (e, look, u),
                    _ => (eye, eye + forward, up),
                };
                self.scene.camera = Some(CameraDesc { eye, target, up, fov_deg: fov, left_handed, loc: loc.clone() });
                self.coordinate_systems.insert("camera".into(), world_from_camera);
                self.unused(
                    &p,
                    "Camera \"perspective\"",
                    &["lensradius", "focaldistance", "screenwindow", "frameaspectratio", "shutteropen", "shutterclose"],
                );
            }
            "Film" => {
                let kind = string_arg(t, at, loc, name)?;
                let p = params::parse(t, at)?;
                if !matches!(kind.as_str(), "rgb" | "gbuffer" | "spectral") {
                    return Err(err(
                        loc,
                        format!(
                            "Film \"{}\" is not supported: \"rgb\" (or gbuffer, spectral, read as rgb)",
                            short(&kind)
                        ),
                    ));
                }
                let res = |n: &str, d: i64| -> Result<u32, String> {
                    let v = p.integer(n, d)?;
                    u32::try_from(v)
                        .ok()
                        .filter(|&v| (1..=65536).contains(&v))
                        .ok_or_else(|| err(loc, format!("Film: {n} {v} must be within 1 … 65536")))
                };
                self.scene.film = FilmDesc {
                    xresolution: res("xresolution", 1280)?,
                    yresolution: res("yresolution", 720)?,
                    filename: p.string("filename")?,
                    loc: Some(loc.clone()),
                };
                self.unused(&p, "Film", &[]);
            }
            "Sampler" | "PixelFilter" | "Integrator" | "ColorSpace" | "Option" | "Accelerator" => {
                // One argument (a type, or an option's name and value), then parameters.
                if matches!(t.get(*at).map(|t| &t.kind), Some(Kind::Str(_))) {
                    *at += 1;
                }
                if name == "Option"
                    && matches!(t.get(*at).map(|t| &t.kind), Some(Kind::Number(_) | Kind::Str(_) | Kind::Word(_)))
                    && !is_directive(&t[*at])
                {
                    *at += 1;
                }
                params::parse(t, at)?;
                if !self.warned.iter().any(|w| w == name) {
                    self.warned.push(name.to_string());
                    self.warn(err(
                        loc,
                        format!("{name} is ignored (translucent has its own sampling, filtering and integrator)"),
                    ));
                }
            }
            "Include" | "Import" => {
                let file = string_arg(t, at, loc, name)?;
                let path = dir.join(&file);
                self.file(&path, Some(loc), depth + 1)?;
            }
            "MakeNamedMaterial" => {
                let n = string_arg(t, at, loc, name)?;
                let p = params::parse(t, at)?;
                let kind = p
                    .string("type")?
                    .ok_or_else(|| err(loc, format!("MakeNamedMaterial \"{}\": no \"string type\"", short(&n))))?;
                let m = self.material(&kind, &p, loc)?;
                self.named_materials.insert(n, m);
            }
            "NamedMaterial" => {
                let n = string_arg(t, at, loc, name)?;
                self.state.material = self
                    .named_materials
                    .get(&n)
                    .cloned()
                    .ok_or_else(|| err(loc, format!("NamedMaterial: no material named \"{}\"", short(&n))))?;
            }
            "Material" => {
                let kind = string_arg(t, at, loc, name)?;
                let p = params::parse(t, at)?;
                self.state.material = self.material(&kind, &p, loc)?;
            }
            "Texture" => {
                let n = string_arg(t, at, loc, name)?;
                let ty = string_arg(t, at, loc, name)?;
                let class = string_arg(t, at, loc, name)?;
                let p = params::parse(t, at)?;
                if !matches!(ty.as_str(), "spectrum" | "float") {
                    return Err(err(
                        loc,
                        format!(
                            "Texture \"{}\": type \"{}\" is not supported: \"spectrum\" or \"float\"",
                            short(&n),
                            short(&ty)
                        ),
                    ));
                }
                let tex = match class.as_str() {
                    "constant" => self.reflectance(&p, "value", [1.0; 3])?,
                    "checkerboard" => {
                        let dims = p.integer("dimension", 2)?;
                        if dims != 2 {
                            return Err(err(loc, "Texture \"checkerboard\": only dimension 2 is supported"));
                        }
                        Reflectance::Checkerboard {
                            uscale: p.float("uscale", 1.0)?,
                            vscale: p.float("vscale", 1.0)?,
                            tex1: Box::new(self.reflectance(&p, "tex1", [1.0; 3])?),
                            tex2: Box::new(self.reflectance(&p, "tex2", [0.0; 3])?),
                        }
                    }
                    "imagemap" => {
                        let file = p
                            .string("filename")?
                            .ok_or_else(|| err(loc, "Texture \"imagemap\": no \"string filename\""))?;
                        Reflectance::ImageMap { path: dir.join(file) }
                    }
                    other => {
                        return Err(err(
                            loc,
                            format!(
                                "Texture class \"{}\" is not supported: constant, checkerboard, imagemap",
                                short(other)
                            ),
                        ))
                    }
                };
                self.unused(
                    &p,
                    &format!("Texture \"{class}\""),
                    &["filter", "wrap", "encoding", "invert", "mapping", "maxanisotropy"],
                );
                self.textures.insert(n, Texture::Colour(tex));
            }
            "Shape" => {
                let kind = string_arg(t, at, loc, name)?;
                let p = params::parse(t, at)?;
                self.shape(&kind, &p, loc, dir)?;
            }
            "LightSource" => {
                let kind = string_arg(t, at, loc, name)?;
                let p = params::parse(t, at)?;
                self.light(&kind, &p, loc, dir)?;
            }
            other => {
                return Err(err(
                    loc,
                    format!("unknown or unsupported directive '{}' (supported: {SUPPORTED})", short(other)),
                ));
            }
        }
        Ok(())
    }

    fn unused(&mut self, p: &ParamList, what: &str, quiet: &[&str]) {
        for w in p.unused(what) {
            if !quiet.iter().any(|q| w.contains(&format!(" {q}' of"))) {
                self.warn(w);
            }
        }
    }

    /// A colour or a texture reference, resolved.
    fn reflectance(&self, p: &ParamList, name: &str, default: [f64; 3]) -> Result<Reflectance, String> {
        Ok(match p.colour(name, true)? {
            None => Reflectance::Constant(default),
            Some(ColourParam::Rgb(c)) => Reflectance::Constant(c),
            Some(ColourParam::Texture(n)) => match self.textures.get(&n) {
                Some(Texture::Colour(r)) => r.clone(),
                None => {
                    let loc = &p.params.iter().find(|q| q.name == name).expect("found").loc;
                    return Err(err(loc, format!("no texture named \"{}\" (Texture must define it first)", short(&n))));
                }
            },
        })
    }

    fn material(&mut self, kind: &str, p: &ParamList, loc: &Loc) -> Result<MaterialDesc, String> {
        let m = match kind {
            "subsurface" => {
                // A textured reflectance: resolved here, inverted per point by the renderer.
                let texture = match p.colour("reflectance", true)? {
                    Some(ColourParam::Texture(_)) => Some(self.reflectance(p, "reflectance", [0.5; 3])?),
                    _ => None,
                };
                MaterialDesc::Subsurface(subsurface(p, loc, texture)?)
            }
            "diffuse" => MaterialDesc::Diffuse { reflectance: self.reflectance(p, "reflectance", [0.5; 3])? },
            "interface" | "" | "none" => MaterialDesc::Interface,
            other => {
                return Err(err(
                    loc,
                    format!("material \"{}\" is not supported: subsurface, diffuse (interface for none)", short(other)),
                ))
            }
        };
        self.unused(
            p,
            &format!("material \"{kind}\""),
            &["type", "displacement", "normalmap", "uroughness", "vroughness"],
        );
        Ok(m)
    }

    fn shape(&mut self, kind: &str, p: &ParamList, loc: &Loc, dir: &Path) -> Result<(), String> {
        let mut raw = match kind {
            "trianglemesh" => {
                let positions =
                    p.triples("P", "point3")?.ok_or_else(|| err(loc, "Shape \"trianglemesh\": no \"point3 P\""))?;
                if positions.len() > crate::mesh::MAX_ELEMENTS {
                    return Err(err(
                        loc,
                        format!("Shape \"trianglemesh\": more than {} vertices", crate::mesh::MAX_ELEMENTS),
                    ));
                }
                let indices = match p.integers("indices")? {
                    Some(i) => i,
                    None if positions.len() == 3 => vec![0, 1, 2],
                    None => return Err(err(
                        loc,
                        "Shape \"trianglemesh\": no \"integer indices\" (only a single triangle may leave them out)",
                    )),
                };
                if !indices.len().is_multiple_of(3) {
                    return Err(err(
                        loc,
                        format!("Shape \"trianglemesh\": {} indices is not a multiple of 3", indices.len()),
                    ));
                }
                if let Some(i) = indices.iter().find(|&&i| i < 0 || i as usize >= positions.len()) {
                    return Err(err(
                        loc,
                        format!("Shape \"trianglemesh\": index {i} is out of range ({} vertices)", positions.len()),
                    ));
                }
                let normals = p.triples("N", "normal3")?;
                let uvs = p.pairs("uv")?;
                for (what, n) in [("N", normals.as_ref().map(Vec::len)), ("uv", uvs.as_ref().map(Vec::len))] {
                    if n.is_some_and(|n| n != positions.len()) {
                        return Err(err(
                            loc,
                            format!(
                                "Shape \"trianglemesh\": {} values of \"{what}\" for {} vertices",
                                n.unwrap_or(0),
                                positions.len()
                            ),
                        ));
                    }
                }
                let f = |v: &[f64; 3]| Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32);
                crate::mesh::RawMesh {
                    positions: positions.iter().map(f).collect(),
                    normals: normals.map(|n| n.iter().map(f).collect()),
                    uvs: uvs.map(|u| u.iter().map(|v| Vec2::new(v[0] as f32, v[1] as f32)).collect()),
                    indices: indices.iter().map(|&i| i as u32).collect(),
                }
            }
            "plymesh" => {
                let file =
                    p.string("filename")?.ok_or_else(|| err(loc, "Shape \"plymesh\": no \"string filename\""))?;
                let path = dir.join(&file);
                let name = path.to_string_lossy().to_ascii_lowercase();
                if !(name.ends_with(".ply") || name.ends_with(".ply.gz")) {
                    return Err(err(
                        loc,
                        format!("Shape \"plymesh\": \"{}\" is not a .ply or .ply.gz file", short(&file)),
                    ));
                }
                if p.params.iter().any(|q| q.name == "displacement") {
                    return Err(err(loc, "Shape \"plymesh\": displacement is not supported"));
                }
                crate::mesh::read_raw(&path).map_err(|e| err(loc, format!("Shape \"plymesh\": {e}")))?
            }
            "sphere" => {
                let radius = p.float("radius", 1.0)?;
                let (zmin, zmax, phimax) =
                    (p.float("zmin", -radius)?, p.float("zmax", radius)?, p.float("phimax", 360.0)?);
                if zmin > -radius || zmax < radius || phimax < 360.0 {
                    return Err(err(
                        loc,
                        "Shape \"sphere\": only whole spheres are supported (zmin, zmax, phimax at their defaults)",
                    ));
                }
                if !(radius.abs() > 0.0 && radius.is_finite()) {
                    return Err(err(loc, format!("Shape \"sphere\": radius {radius} must be non-zero")));
                }
                // pbrt's sphere has its poles on z; the tessellation's are on y: turned.
                let m = crate::mesh::Mesh::sphere(1.0, 48);
                let turn = |v: Vec3| Vec3::new(v.x, -v.z, v.y);
                crate::mesh::RawMesh {
                    positions: m.positions.iter().map(|&v| turn(v) * radius as f32).collect(),
                    normals: Some(m.normals.iter().map(|&v| turn(v) * radius.signum() as f32).collect()),
                    uvs: None,
                    indices: m.indices,
                }
            }
            other => {
                return Err(err(
                    loc,
                    format!("Shape \"{}\" is not supported: trianglemesh, plymesh, sphere", short(other)),
                ));
            }
        };
        self.unused(p, &format!("Shape \"{kind}\""), &["alpha", "emission"]);
        if matches!(self.state.material, MaterialDesc::Interface) {
            return Ok(()); // an invisible boundary
        }
        // To world space: positions by the CTM, normals by its inverse transpose; a transformation
        // that swaps handedness, or ReverseOrientation, turns the winding (pbrt's orientation rule).
        let m = self.state.ctm;
        let normal_m = m.inverse().transpose();
        let swaps = m.determinant() < 0.0;
        let flip = if self.state.reverse_orientation { -1.0 } else { 1.0 };
        if m != DMat4::IDENTITY {
            for v in &mut raw.positions {
                *v = m.transform_point3(v.as_dvec3()).as_vec3();
            }
            if let Some(normals) = &mut raw.normals {
                for n in normals.iter_mut() {
                    *n = (normal_m.transform_vector3(n.as_dvec3()).normalize_or_zero() * flip).as_vec3();
                }
            }
        } else if let Some(normals) = raw.normals.as_mut().filter(|_| flip < 0.0) {
            // In world space already: the file's numbers as they are (as `--mesh` reads them).
            normals.iter_mut().for_each(|n| *n = -*n);
        }
        if self.state.reverse_orientation != swaps {
            for t in raw.indices.chunks_exact_mut(3) {
                t.swap(1, 2);
            }
        }
        if let Some(i) = raw.positions.iter().position(|p| !p.is_finite()) {
            return Err(err(loc, format!("Shape \"{kind}\": vertex {i} is not finite once transformed")));
        }
        self.scene.objects.push(Object {
            mesh: raw,
            material: self.state.material.clone(),
            shape: kind.to_string(),
            loc: loc.clone(),
        });
        Ok(())
    }

    fn light(&mut self, kind: &str, p: &ParamList, loc: &Loc, dir: &Path) -> Result<(), String> {
        let m = self.state.ctm;
        let scale = p.float("scale", 1.0)?;
        let colour = |name: &str| -> Result<[f64; 3], String> {
            match p.colour(name, false)? {
                Some(ColourParam::Rgb(c)) => Ok(c),
                Some(ColourParam::Texture(_)) => unreachable!("textures refused"),
                None => Ok([1.0; 3]),
            }
        };
        let point = |name: &str, d: [f64; 3]| -> Result<DVec3, String> {
            Ok(m.transform_point3(DVec3::from(p.point(name, "point3", d)?)))
        };
        if p.params.iter().any(|q| q.name == "power") {
            return Err(err(loc, format!("LightSource \"{kind}\": \"power\" is not supported: give \"scale\"")));
        }
        let light = match kind {
            "distant" => LightDesc::Distant {
                from: point("from", [0.0; 3])?,
                to: point("to", [0.0, 0.0, 1.0])?,
                l: colour("L")?,
                scale,
                loc: loc.clone(),
            },
            "point" => LightDesc::Point { from: point("from", [0.0; 3])?, i: colour("I")?, scale, loc: loc.clone() },
            "spot" => LightDesc::Spot {
                from: point("from", [0.0; 3])?,
                to: point("to", [0.0, 0.0, 1.0])?,
                coneangle: p.float("coneangle", 30.0)?,
                // pbrt-v4's name (SpotLight::Create, after RenderMan's spotlight shader).
                conedelta: p.float("conedeltaangle", 5.0)?,
                i: colour("I")?,
                scale,
                loc: loc.clone(),
            },
            "infinite" => {
                let filename = p.string("filename")?.map(|f| dir.join(f));
                let l = if filename.is_none() { Some(colour("L")?) } else { None };
                let frame = glam::DMat3::from_mat4(m);
                LightDesc::Infinite { filename, l, scale, frame, loc: loc.clone() }
            }
            other => {
                return Err(err(
                    loc,
                    format!("LightSource \"{}\" is not supported: distant, point, spot, infinite", short(other)),
                ))
            }
        };
        self.unused(p, &format!("LightSource \"{kind}\""), &[]);
        self.scene.lights.push(light);
        Ok(())
    }
}

/// pbrt-v4's `subsurface` material, in its four forms (see `SubsurfaceMaterial::Create`);
/// `texture`: the `reflectance` when it is a texture (its coefficients are then the texture's
/// mean's, made when it is loaded: `pbrt::render_settings`).
fn subsurface(p: &ParamList, loc: &Loc, texture: Option<Reflectance>) -> Result<Subsurface, String> {
    let mut g = p.float("g", 0.0)?;
    let scale = p.float("scale", 1.0)?;
    let eta = p.float("eta", 1.33)?;
    let roughness = p.float("roughness", 0.0)?;
    let remap = p.boolean("remaproughness", true)?;
    let colour = |name: &str| -> Result<Option<[f64; 3]>, String> {
        match p.colour(name, false)? {
            Some(ColourParam::Rgb(c)) => Ok(Some(c)),
            _ => Ok(None),
        }
    };
    let (sigma_a, sigma_s, source) = if let Some(name) = p.string("name")? {
        let (a, s) = pbrt_medium(&name).ok_or_else(|| {
            let names: Vec<&str> = super::PBRT_MEDIA.iter().map(|m| m.0).collect();
            err(
                loc,
                format!(
                    "subsurface: no measured medium named \"{}\" in pbrt-v4's table (its names: {})",
                    short(&name),
                    names.join(", ")
                ),
            )
        })?;
        // pbrt: the table gives reduced scattering coefficients, so g is 0.
        g = 0.0;
        (a, s, SubsurfaceSource::Named(name))
    } else {
        match (colour("sigma_a")?, colour("sigma_s")?) {
            (Some(a), Some(s)) => (a, s, SubsurfaceSource::Coefficients),
            (Some(_), None) => return Err(err(loc, "subsurface: \"sigma_a\" given without \"sigma_s\"")),
            (None, Some(_)) => return Err(err(loc, "subsurface: \"sigma_s\" given without \"sigma_a\"")),
            (None, None) => match (if texture.is_some() { None } else { colour("reflectance")? }, texture) {
                (_, Some(texture)) => {
                    let mfp = colour("mfp")?.unwrap_or([1.0; 3]);
                    // Checked now at mid-grey; the texture's mean replaces it once loaded.
                    let (a, s) = from_reflectance([0.5; 3], mfp, g, eta)
                        .map_err(|why| err(loc, format!("subsurface: {why}")))?;
                    (a, s, SubsurfaceSource::Texture { texture, mfp })
                }
                (Some(r), None) => {
                    let mfp = colour("mfp")?.unwrap_or([1.0; 3]);
                    let (a, s) =
                        from_reflectance(r, mfp, g, eta).map_err(|why| err(loc, format!("subsurface: {why}")))?;
                    (a, s, SubsurfaceSource::Reflectance { reflectance: r, mfp })
                }
                (None, None) => ([0.0011, 0.0024, 0.014], [2.55, 3.21, 3.77], SubsurfaceSource::Default),
            },
        }
    };
    Ok(Subsurface { sigma_a, sigma_s, scale, g, eta, roughness, remap_roughness: remap, source, loc: loc.clone() })
}

fn numbers(t: &[Token], at: &mut usize, n: usize, loc: &Loc, name: &str) -> Result<Vec<f64>, String> {
    let mut v = Vec::with_capacity(n);
    for _ in 0..n {
        match t.get(*at) {
            Some(Token { kind: Kind::Number(x), .. }) => {
                v.push(*x);
                *at += 1;
            }
            _ => return Err(err(loc, format!("{name} takes {n} numbers"))),
        }
    }
    Ok(v)
}

/// `[ n numbers ]` (pbrt also accepts them without brackets).
fn bracketed(t: &[Token], at: &mut usize, n: usize, loc: &Loc, name: &str) -> Result<Vec<f64>, String> {
    let open = matches!(t.get(*at).map(|t| &t.kind), Some(Kind::Open));
    if open {
        *at += 1;
    }
    let v = numbers(t, at, n, loc, name)?;
    if open {
        match t.get(*at) {
            Some(Token { kind: Kind::Close, .. }) => *at += 1,
            _ => return Err(err(loc, format!("{name} takes [ {n} numbers ]"))),
        }
    }
    Ok(v)
}

fn string_arg(t: &[Token], at: &mut usize, loc: &Loc, name: &str) -> Result<String, String> {
    match t.get(*at) {
        Some(Token { kind: Kind::Str(s), .. }) => {
            *at += 1;
            Ok(s.clone())
        }
        _ => Err(err(loc, format!("{name} needs a quoted string argument"))),
    }
}

fn is_directive(t: &Token) -> bool {
    matches!(&t.kind, Kind::Word(w) if w.chars().next().is_some_and(char::is_uppercase))
}

fn describe(k: &Kind) -> String {
    match k {
        Kind::Str(s) => format!("the string \"{}\"", short(s)),
        Kind::Number(n) => format!("the number {n}"),
        Kind::Open => "'['".into(),
        Kind::Close => "']'".into(),
        Kind::Word(w) => format!("'{}'", short(w)),
    }
}
