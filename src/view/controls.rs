//! What the mouse, the keys and `--script` lines do to the view: one set of actions, so that a
//! script drives exactly the code paths of the hands.

use std::path::{Path, PathBuf};

use glam::{Quat, Vec3};

use crate::bad_input;
use crate::cli::{finite_f32 as number, triple};
use crate::error::Result;
use crate::physics::Model;
use crate::scene::{Camera, Light};

/// One change to the view, from a script line, a key or a mouse drag.
#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    /// Turn the camera about the target: degrees about the up axis, then degrees upward.
    Orbit {
        right_deg: f32,
        up_deg: f32,
    },
    /// Move camera and target sideways, in fractions of the view's height at the target.
    Pan {
        right: f32,
        up: f32,
    },
    /// Divide the camera's distance to the target by this factor (> 1 comes closer).
    Zoom(f32),
    /// Turn every light as seen from the camera: directions about the view's axes, point lights
    /// about the object's centre.
    TurnLights {
        right_deg: f32,
        up_deg: f32,
    },
    /// Replace the first light.
    SetLight(Light),
    /// Replace light K (0-based, among the lights that are not the environment's samples).
    SetLightAt(usize, Light),
    /// Add a light (after the others, before the environment's samples).
    AddLight(Light),
    /// Remove light K (0-based, as for `SetLightAt`).
    RemoveLight(usize),
    /// Change the environment: its map, scale, rotation or sample count.
    Environment(EnvEdit),
    /// A material preset by name.
    Material(String),
    Set(Setting),
    /// A mouse drag of this many pixels, as the hands make it: it counts as interaction, so the
    /// frames that follow are previews until the view is still.
    Drag(Drag, f32, f32),
    /// Render and present this many frames before the next line (skipped frames count while the
    /// window is minimised).
    Frames(u32),
    /// Write the last presented image, refined to full resolution first if it was a preview.
    Screenshot(PathBuf),
    /// Resize the window; `0 0` minimises it.
    Resize(u32, u32),
    /// Pause or play a deforming mesh.
    TogglePause,
    /// Write a Chrome trace of the GPU timings of the next this many frames.
    Trace(u32, PathBuf),
    Quit,
}

/// What a mouse drag moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Drag {
    Orbit,
    Pan,
    Light,
}

/// A change to the environment light (`--env` and its flags, or a pbrt scene's `infinite`).
#[derive(Clone, Debug, PartialEq)]
pub enum EnvEdit {
    /// A new map, as `--env` names it (FILE, const:L, sky[:E:A]); `None` removes it.
    Map(Option<String>),
    /// `--env-scale`.
    Scale(f32),
    /// `--env-rotate`: degrees about the up axis, on top of the map's own frame.
    Rotate(f32),
    /// `--env-samples`.
    Samples(u32),
}

#[derive(Clone, Debug, PartialEq)]
pub enum Setting {
    Epsilon(f32),
    /// Stops; `None` is automatic exposure.
    Exposure(Option<f32>),
    Specular(bool),
    Roughness(f32),
    Model(Model),
    BruteForce(bool),
    SigmaA([f64; 3]),
    SigmaS([f64; 3]),
    G([f64; 3]),
    Eta(f64),
    /// Sample points (a new hierarchy).
    Samples(u32),
    /// The debug view drawn over the shading.
    Show(crate::frame_desc::Show),
}

/// A parsed script line, with its 1-based number for messages.
#[derive(Clone, Debug, PartialEq)]
pub struct ScriptLine {
    pub number: usize,
    pub text: String,
    pub action: Action,
}

/// Reads and checks a whole script before any window opens; a bad line is bad input naming it.
pub fn load_script(path: &Path) -> Result<Vec<ScriptLine>> {
    let text = std::fs::read_to_string(path).map_err(|e| bad_input!("--script {}: {e}", path.display()))?;
    parse_script(&text)
        .map_err(|(number, line, why)| bad_input!("--script {} line {number}: {why} (`{line}`)", path.display()))
}

/// Lines are `command arguments…`; blank lines and `#` comments are skipped. On error: the line's
/// number, its text and why.
pub fn parse_script(text: &str) -> std::result::Result<Vec<ScriptLine>, (usize, String, String)> {
    let mut lines = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let action = parse_line(line).map_err(|why| (i + 1, line.to_string(), why))?;
        lines.push(ScriptLine { number: i + 1, text: line.to_string(), action });
    }
    Ok(lines)
}

/// A light's number on a script line (1 is the first), as a 0-based index.
fn light_number(s: &str) -> std::result::Result<usize, String> {
    match s.parse::<usize>() {
        Ok(k) if k >= 1 => Ok(k - 1),
        _ => Err(format!("light '{s}': lights are numbered from 1")),
    }
}

fn count(s: &str) -> std::result::Result<u32, String> {
    s.parse().map_err(|_| format!("'{s}' is not a whole number ≥ 0"))
}

fn on_off(s: &str) -> std::result::Result<bool, String> {
    match s {
        "on" | "true" | "1" => Ok(true),
        "off" | "false" | "0" => Ok(false),
        _ => Err(format!("'{s}' is neither on nor off")),
    }
}

fn output_path(s: &str, extension: &str) -> std::result::Result<PathBuf, String> {
    let path = PathBuf::from(s);
    if path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()) != Some(extension.to_string()) {
        return Err(format!("{s}: the file must end in .{extension}"));
    }
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        if !dir.is_dir() {
            return Err(format!("{s}: the folder {} does not exist", dir.display()));
        }
    }
    Ok(path)
}

/// One script line (already trimmed, not empty).
pub fn parse_line(line: &str) -> std::result::Result<Action, String> {
    let words: Vec<&str> = line.split_whitespace().collect();
    let args = &words[1..];
    let want = |n: usize, usage: &str| {
        if args.len() == n {
            Ok(())
        } else {
            Err(format!("expected `{usage}`"))
        }
    };
    let action = match words[0] {
        "orbit" => {
            want(2, "orbit RIGHT_DEG UP_DEG")?;
            Action::Orbit { right_deg: number(args[0])?, up_deg: number(args[1])? }
        }
        "pan" => {
            want(2, "pan RIGHT UP (fractions of the view's height)")?;
            Action::Pan { right: number(args[0])?, up: number(args[1])? }
        }
        "zoom" => {
            want(1, "zoom FACTOR")?;
            let f = number(args[0])?;
            if f <= 0.0 {
                return Err(format!("zoom {f}: the factor must be positive"));
            }
            Action::Zoom(f)
        }
        "light" => match args {
            ["turn", r, u] => Action::TurnLights { right_deg: number(r)?, up_deg: number(u)? },
            ["add", spec] => Action::AddLight(crate::cli::light_spec(spec)?),
            ["remove", k] => Action::RemoveLight(light_number(k)?),
            [k, spec] if k.parse::<u64>().is_ok() => Action::SetLightAt(light_number(k)?, crate::cli::light_spec(spec)?),
            [spec] => Action::SetLight(crate::cli::light_spec(spec)?),
            _ => {
                return Err(format!(
                    "expected `light SPEC` ({}), `light N SPEC`, `light add SPEC`, `light remove N` or `light turn RIGHT_DEG UP_DEG`",
                    crate::cli::LIGHT_FORMS
                ))
            }
        },
        "env" => Action::Environment(match args {
            ["off"] => EnvEdit::Map(None),
            ["scale", v] => {
                let v = number(v)?;
                if v < 0.0 {
                    return Err(format!("env scale {v}: must be ≥ 0"));
                }
                EnvEdit::Scale(v)
            }
            ["rotate", deg] => EnvEdit::Rotate(number(deg)?),
            ["samples", k] => {
                let k = count(k)?;
                if !(1..=crate::environment::MAX_SAMPLES).contains(&k) {
                    return Err(format!("env samples {k}: must be between 1 and {}", crate::environment::MAX_SAMPLES));
                }
                EnvEdit::Samples(k)
            }
            // Checked (the file read) when the script is loaded, so a bad map is bad input at once.
            [spec] => {
                crate::settings::environment_radiance(spec).map_err(|e| e.to_string())?;
                EnvEdit::Map(Some(spec.to_string()))
            }
            _ => {
                return Err(
                    "expected `env FILE|const:L|sky[:E:A]`, `env off`, `env scale S`, `env rotate DEG` or `env samples K`"
                        .into(),
                )
            }
        }),
        "material" => {
            want(1, "material NAME")?;
            crate::materials::Material::find(args[0]).map_err(|e| e.to_string())?;
            Action::Material(args[0].to_string())
        }
        "set" => {
            want(2, "set NAME VALUE")?;
            let value = args[1];
            Action::Set(match args[0] {
                "epsilon" => {
                    let e = number(value)?;
                    if e < 0.0 {
                        return Err(format!("epsilon {e}: must be ≥ 0"));
                    }
                    Setting::Epsilon(e)
                }
                "exposure" if value == "auto" => Setting::Exposure(None),
                "exposure" => Setting::Exposure(Some(number(value)?)),
                "specular" => Setting::Specular(on_off(value)?),
                "roughness" => {
                    let r = number(value)?;
                    crate::frame_desc::check_roughness(r, "roughness").map_err(|e| e.to_string())?;
                    Setting::Roughness(r)
                }
                "model" => Setting::Model(
                    Model::from_name(value).ok_or_else(|| format!("model '{value}': {}", Model::names()))?,
                ),
                "brute-force" => Setting::BruteForce(on_off(value)?),
                "sigma-a" => Setting::SigmaA(triple(value)?),
                "sigma-s" => Setting::SigmaS(triple(value)?),
                "g" => Setting::G(triple(value)?),
                "eta" => Setting::Eta(number(value)? as f64),
                "samples" => {
                    let n = count(value)?;
                    if n < 2 {
                        return Err(format!("samples {n}: at least 2"));
                    }
                    Setting::Samples(n)
                }
                "show" => Setting::Show(match value.split_once(':') {
                    None if value == "shading" => crate::frame_desc::Show::Shading,
                    None if value == "samples" => crate::frame_desc::Show::Samples,
                    Some(("tree", level)) => crate::frame_desc::Show::Tree(count(level)?),
                    _ => return Err(format!("show '{value}': shading, samples or tree:LEVEL")),
                }),
                other => {
                    return Err(format!(
                        "unknown setting '{other}' (epsilon, exposure, specular, roughness, model, brute-force, sigma-a, sigma-s, g, eta, samples, show)"
                    ))
                }
            })
        }
        "drag" => {
            want(3, "drag orbit|pan|light DX DY (pixels)")?;
            let kind = match args[0] {
                "orbit" => Drag::Orbit,
                "pan" => Drag::Pan,
                "light" => Drag::Light,
                other => return Err(format!("drag '{other}': orbit, pan or light")),
            };
            Action::Drag(kind, number(args[1])?, number(args[2])?)
        }
        "frames" => {
            want(1, "frames N")?;
            Action::Frames(count(args[0])?)
        }
        "screenshot" => {
            want(1, "screenshot FILE.png")?;
            Action::Screenshot(output_path(args[0], "png")?)
        }
        "resize" => {
            want(2, "resize WIDTH HEIGHT")?;
            let (w, h) = (count(args[0])?, count(args[1])?);
            if (w == 0) != (h == 0) || w > 16384 || h > 16384 {
                return Err(format!("resize {w} {h}: both 0 (minimise) or both between 1 and 16384"));
            }
            Action::Resize(w, h)
        }
        "pause" => {
            want(0, "pause")?;
            Action::TogglePause
        }
        "trace" => {
            want(2, "trace FRAMES FILE.json")?;
            Action::Trace(count(args[0])?.max(1), output_path(args[1], "json")?)
        }
        "quit" => {
            want(0, "quit")?;
            Action::Quit
        }
        other => return Err(format!(
            "unknown command '{other}' (orbit, pan, zoom, light, env, drag, material, set, frames, screenshot, resize, pause, trace, quit)"
        )),
    };
    Ok(action)
}

/// The camera's right and up directions (unit, perpendicular to the view direction).
fn camera_axes(camera: &Camera) -> (Vec3, Vec3) {
    let forward = (camera.target - camera.eye).normalize();
    let right = forward.cross(camera.up).normalize();
    (right, right.cross(forward))
}

/// Turns the eye about the target (see [`Action::Orbit`]). Never over the poles: the elevation
/// stops 1° short of the up axis.
pub fn orbit(camera: &mut Camera, right_deg: f32, up_deg: f32) {
    let up = camera.up.normalize();
    let offset = camera.eye - camera.target;
    // Positive: the camera moves to its right, so the object seems to turn left.
    let offset = Quat::from_axis_angle(up, right_deg.to_radians()) * offset;
    let (right, _) = camera_axes(&Camera { eye: camera.target + offset, ..*camera });
    let elevation = 90.0 - offset.normalize().dot(up).clamp(-1.0, 1.0).acos().to_degrees();
    let turn = (elevation + up_deg).clamp(-89.0, 89.0) - elevation;
    // About `right` (forward × up), a negative angle lifts the eye.
    camera.eye = camera.target + Quat::from_axis_angle(right, -turn.to_radians()) * offset;
}

pub fn pan(camera: &mut Camera, right: f32, up: f32) {
    let (r, u) = camera_axes(camera);
    let height = 2.0 * (camera.eye - camera.target).length() * (camera.fov_y_deg.to_radians() * 0.5).tan();
    let shift = (r * right + u * up) * height;
    camera.eye += shift;
    camera.target += shift;
}

pub fn zoom(camera: &mut Camera, factor: f32) {
    camera.eye = camera.target + (camera.eye - camera.target) / factor;
}

/// See [`Action::TurnLights`].
pub fn turn_lights(lights: &mut [Light], camera: &Camera, centre: Vec3, right_deg: f32, up_deg: f32) {
    let (right, up) = camera_axes(camera);
    // Dragging right moves the light to the right as seen on screen: about the screen's up axis.
    let turn = Quat::from_axis_angle(right, -up_deg.to_radians()) * Quat::from_axis_angle(up, right_deg.to_radians());
    for light in lights {
        *light = light.turned(turn, centre);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera { eye: Vec3::new(0.0, 0.0, 5.0), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 40.0 }
    }

    #[test]
    fn orbit_and_back_returns_the_camera() {
        let mut c = camera();
        orbit(&mut c, 30.0, 20.0);
        assert!((c.eye - camera().eye).length() > 1.0);
        assert!((c.eye.length() - 5.0).abs() < 1e-4, "distance kept");
        assert!(c.eye.y > 0.0, "up is up");
        assert!(c.eye.x > 0.0, "right is right");
        orbit(&mut c, 0.0, -20.0);
        orbit(&mut c, -30.0, 0.0);
        assert!((c.eye - camera().eye).length() < 1e-4, "{:?}", c.eye);
    }

    #[test]
    fn orbit_stops_short_of_the_poles() {
        let mut c = camera();
        orbit(&mut c, 0.0, 95.0);
        assert!(c.eye.z > 0.0 && c.eye.y > 4.99, "stops at 89°, on the near side: {}", c.eye);
        orbit(&mut c, 0.0, -200.0);
        assert!(c.eye.z > 0.0 && c.eye.y < -4.99, "and at -89°: {}", c.eye);
    }

    #[test]
    fn zoom_and_pan() {
        let mut c = camera();
        zoom(&mut c, 2.0);
        assert!((c.eye.z - 2.5).abs() < 1e-6);
        pan(&mut c, 0.5, 0.0);
        assert!(c.target.x > 0.0 && (c.eye - c.target).length() - 2.5 < 1e-5);
    }

    #[test]
    fn lights_turn_with_the_drag() {
        let mut lights = [Light::Directional { toward: Vec3::Z, irradiance: Vec3::ONE }];
        turn_lights(&mut lights, &camera(), Vec3::ZERO, 180.0, 0.0);
        let Light::Directional { toward, .. } = lights[0] else { unreachable!() };
        assert!((toward - Vec3::NEG_Z).length() < 1e-5, "front light dragged to the back: {toward}");
    }

    #[test]
    fn spots_turn_position_and_axis_together() {
        // A spot in front of the centre, aimed at it: dragged to the back, still aimed at it.
        let spot = Light::spot(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, 20.0, 5.0, Vec3::ONE).unwrap();
        let mut lights = [spot];
        turn_lights(&mut lights, &camera(), Vec3::ZERO, 180.0, 0.0);
        let Light::Spot { position, axis, cone_deg, delta_deg, .. } = lights[0] else { unreachable!() };
        assert!((position - Vec3::new(0.0, 0.0, -3.0)).length() < 1e-5, "{position}");
        assert!((axis - Vec3::Z).length() < 1e-5, "{axis}");
        assert_eq!((cone_deg, delta_deg), (20.0, 5.0));
    }

    #[test]
    fn script_lines_parse_or_name_the_problem() {
        let script = "# a comment\norbit 30 0\n\nzoom 1.2\nlight dir:-0.3,0.7,-0.6\nmaterial skin1\nset epsilon 0.05\nframes 3\nscreenshot a.png\nresize 640 480\nquit\n";
        let lines = parse_script(script).unwrap();
        assert_eq!(lines.len(), 9);
        assert_eq!(lines[0].number, 2);
        assert_eq!(lines[0].action, Action::Orbit { right_deg: 30.0, up_deg: 0.0 });
        assert_eq!(lines[4].action, Action::Set(Setting::Epsilon(0.05)));
        let edits = parse_script(
            "light add point:1,2,3:4\nlight 2 dir:0,1,0\nlight remove 1\nenv sky:20:90\nenv scale 0.5\nenv rotate 30\nenv samples 16\nenv off\n",
        )
        .unwrap();
        let actions: Vec<Action> = edits.into_iter().map(|l| l.action).collect();
        assert_eq!(
            actions,
            vec![
                Action::AddLight(Light::Point { position: Vec3::new(1.0, 2.0, 3.0), intensity: Vec3::splat(4.0) }),
                Action::SetLightAt(1, Light::Directional { toward: Vec3::Y, irradiance: Vec3::ONE }),
                Action::RemoveLight(0),
                Action::Environment(EnvEdit::Map(Some("sky:20:90".into()))),
                Action::Environment(EnvEdit::Scale(0.5)),
                Action::Environment(EnvEdit::Rotate(30.0)),
                Action::Environment(EnvEdit::Samples(16)),
                Action::Environment(EnvEdit::Map(None)),
            ]
        );
        let spot = parse_script("light spot:0,2,0:0,0,0:30:5:2\n").unwrap();
        assert_eq!(
            spot[0].action,
            Action::SetLight(Light::spot(Vec3::new(0.0, 2.0, 0.0), Vec3::ZERO, 30.0, 5.0, Vec3::splat(2.0)).unwrap())
        );
        for (bad, needle) in [
            ("orbit 30", "expected"),
            ("zoom -1", "positive"),
            ("frobnicate", "unknown command"),
            ("material unobtainium", "unobtainium"),
            ("set epsilon x", "not a number"),
            ("resize 0 10", "both 0"),
            ("screenshot a.jpg", ".png"),
            ("light dir:0,0", "X,Y,Z"),
            ("light spot:0,1,0:0,0,0:200", "cone angle 200°"),
            ("light spot:0,1,0", "spot:X,Y,Z:TX,TY,TZ:ANGLE"),
            ("light", "light SPEC"),
            ("light 0 dir:0,1,0", "numbered from 1"),
            ("light add spot:0,1,0", "spot:X,Y,Z:TX,TY,TZ:ANGLE"),
            ("env", "env FILE"),
            ("env scale -1", "≥ 0"),
            ("env samples 0", "between 1 and 4096"),
            ("env no-such-map.exr", "no-such-map.exr"),
        ] {
            let (n, _, why) = parse_script(&format!("quit\n{bad}\n")).unwrap_err();
            assert_eq!(n, 2, "{bad}");
            assert!(why.contains(needle), "{bad}: {why}");
        }
    }
}
