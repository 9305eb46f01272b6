//! The viewer's panel (egui): the settings, each change an [`Action`] applied after the frame
//! (so it takes effect on the next one), and the timings of the last frames.

use egui::{Color32, RichText, SliderClamping::Edits};

use glam::Vec3;

use super::controls::{Action, EnvEdit, Setting};
use crate::frame_desc::Show;
use crate::physics::Model;
use crate::scene::Light;

/// What the panel shows: the current settings and the last frames' numbers.
pub struct PanelState {
    /// The first translucent object's material (none where nothing is translucent).
    pub material: Option<crate::materials::Material>,
    pub model: Model,
    pub epsilon: f32,
    pub samples: u32,
    /// Stops; `None`: automatic.
    pub exposure: Option<f32>,
    pub specular: bool,
    pub roughness: f32,
    pub brute_force: bool,
    pub show: Show,
    /// Some(playing) when the mesh is animated.
    pub playing: Option<bool>,
    pub device: String,
    /// e.g. "512x512 refined in 4012 ms".
    pub last_frame: String,
    pub fps: f64,
    /// Nodes and points evaluated per pixel, when counted (`--profile`).
    pub work_per_pixel: Option<(f64, f64)>,
    /// Per-pass GPU milliseconds of the last full frame.
    pub passes: Vec<(String, f64)>,
    /// Refinement of the frame in progress, 0 to 1.
    pub refining: Option<f32>,
    /// The user's lights (not the environment's samples), in order.
    pub lights: Vec<Light>,
    /// The environment light, when there is one.
    pub environment: Option<EnvironmentState>,
}

/// The environment as the panel shows it.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentState {
    pub name: String,
    pub scale: f32,
    /// Degrees about the up axis on top of the map's own frame.
    pub rotate_deg: f32,
    pub samples: u32,
}

/// Three drag values for a vector; `Some` when one was changed.
fn vector(ui: &mut egui::Ui, label: &str, v: Vec3, speed: f64) -> Option<Vec3> {
    let mut a = v.to_array();
    ui.horizontal(|ui| {
        ui.label(label);
        for c in &mut a {
            ui.add(egui::DragValue::new(c).speed(speed).max_decimals(3));
        }
    });
    (Vec3::from(a) != v).then(|| Vec3::from(a))
}

/// The lights, each editable where it is (direction or position, strength), removable, and
/// buttons that add one; then the environment: its map (as `--env` names it), scale, rotation
/// about the up axis and sample count.
fn lights_and_environment(ui: &mut egui::Ui, s: &PanelState, actions: &mut Vec<Action>) {
    egui::CollapsingHeader::new("Lights").default_open(false).show(ui, |ui| {
        for (k, light) in s.lights.iter().enumerate() {
            ui.push_id(k, |ui| {
                let mut edited = *light;
                ui.horizontal(|ui| {
                    ui.label(format!(
                        "{} {}",
                        k + 1,
                        match light {
                            Light::Directional { .. } => "directional",
                            Light::Point { .. } => "point",
                            Light::Spot { .. } => "spot",
                        }
                    ));
                    // The last light stays unless the environment lights the scene.
                    let removable = s.lights.len() > 1 || s.environment.is_some();
                    if removable && ui.small_button("remove").clicked() {
                        actions.push(Action::RemoveLight(k));
                    }
                });
                match &mut edited {
                    Light::Directional { toward, irradiance } => {
                        if let Some(v) = vector(ui, "toward", *toward, 0.01) {
                            *toward = v;
                        }
                        if let Some(v) = vector(ui, "E", *irradiance, 0.01) {
                            *irradiance = v.max(Vec3::ZERO);
                        }
                    }
                    Light::Point { position, intensity } | Light::Spot { position, intensity, .. } => {
                        if let Some(v) = vector(ui, "at", *position, 0.02) {
                            *position = v;
                        }
                        if let Some(v) = vector(ui, "I", *intensity, 0.05) {
                            *intensity = v.max(Vec3::ZERO);
                        }
                    }
                }
                if let Light::Directional { toward, .. } = &mut edited {
                    if *toward == Vec3::ZERO {
                        edited = *light; // a direction of zero length: not taken
                    }
                }
                if edited != *light {
                    actions.push(Action::SetLightAt(k, edited));
                }
            });
        }
        ui.horizontal(|ui| {
            if ui.button("add directional").clicked() {
                actions.push(Action::AddLight(Light::Directional { toward: Vec3::Y, irradiance: Vec3::ONE }));
            }
            if ui.button("add point").clicked() {
                actions.push(Action::AddLight(Light::Point {
                    position: Vec3::new(0.0, 2.0, 2.0),
                    intensity: Vec3::splat(4.0),
                }));
            }
        });
    });
    egui::CollapsingHeader::new("Environment").default_open(false).show(ui, |ui| {
        // The map being typed lives in egui's memory between frames.
        let id = ui.id().with("env map");
        let mut spec = ui.data_mut(|d| d.get_temp::<String>(id)).unwrap_or_default();
        ui.horizontal(|ui| {
            ui.add(egui::TextEdit::singleline(&mut spec).hint_text("FILE, const:L or sky:E:A").desired_width(150.0));
            if ui.button("set").clicked() && !spec.trim().is_empty() {
                actions.push(Action::Environment(EnvEdit::Map(Some(spec.trim().to_string()))));
            }
            if s.environment.is_some() && ui.button("off").clicked() {
                actions.push(Action::Environment(EnvEdit::Map(None)));
            }
        });
        ui.data_mut(|d| d.insert_temp(id, spec));
        let Some(env) = &s.environment else {
            ui.label("no environment");
            return;
        };
        ui.label(&env.name);
        let mut scale = env.scale;
        ui.add(
            egui::DragValue::new(&mut scale)
                .speed(0.01)
                .range(0.0..=1e6)
                .clamp_existing_to_range(false)
                .prefix("scale "),
        );
        if scale != env.scale {
            actions.push(Action::Environment(EnvEdit::Scale(scale)));
        }
        let mut rotate = env.rotate_deg;
        ui.add(egui::Slider::new(&mut rotate, -180.0..=180.0).clamping(Edits).text("rotation °"));
        if rotate != env.rotate_deg {
            actions.push(Action::Environment(EnvEdit::Rotate(rotate)));
        }
        let mut samples = env.samples;
        let response = ui.add(
            egui::DragValue::new(&mut samples)
                .speed(4)
                .range(1..=crate::environment::MAX_SAMPLES)
                .clamp_existing_to_range(false)
                .prefix("samples "),
        );
        // New samples, a new hierarchy's light layout: only once the drag ends.
        if samples != env.samples && !response.dragged() {
            actions.push(Action::Environment(EnvEdit::Samples(samples)));
        }
    });
}

/// Draws the panel; every change becomes an action in `actions`.
pub fn draw(ctx: &egui::Context, s: &PanelState, actions: &mut Vec<Action>) {
    egui::Window::new("translucent").default_width(260.0).resizable(false).show(ctx, |ui| {
        egui::CollapsingHeader::new("Material").default_open(true).show(ui, |ui| {
            let Some(m) = &s.material else {
                ui.label("nothing in the scene is translucent");
                return;
            };
            let mut name = m.name.clone();
            egui::ComboBox::from_label("preset").selected_text(&name).show_ui(ui, |ui| {
                for preset in crate::materials::Material::presets() {
                    ui.selectable_value(&mut name, preset.name.clone(), &preset.name);
                }
            });
            if name != m.name {
                actions.push(Action::Material(name));
            }
            let per_channel = |ui: &mut egui::Ui, label: &str, values: [f64; 3], speed: f64, max: f64| {
                let mut v = values;
                ui.horizontal(|ui| {
                    ui.label(label);
                    for (c, value) in v.iter_mut().enumerate() {
                        let colour = [Color32::LIGHT_RED, Color32::LIGHT_GREEN, Color32::LIGHT_BLUE][c];
                        ui.add(
                            egui::DragValue::new(value)
                                .speed(speed)
                                .range(0.0..=max)
                                .clamp_existing_to_range(false)
                                .max_decimals(4),
                        )
                        .on_hover_text(RichText::new(["red", "green", "blue"][c]).color(colour));
                    }
                });
                (v != values).then_some(v)
            };
            if let Some(v) = per_channel(ui, "σa [1/mm]", m.sigma_a, 0.001, 100.0) {
                actions.push(Action::Set(Setting::SigmaA(v)));
            }
            // σ's = σs (1 − g), edited as such; σs follows.
            let reduced = [0, 1, 2].map(|c| m.sigma_s[c] * (1.0 - m.g[c]));
            if let Some(v) = per_channel(ui, "σ's [1/mm]", reduced, 0.01, 1000.0) {
                actions.push(Action::Set(Setting::SigmaS([0, 1, 2].map(|c| v[c] / (1.0 - m.g[c]).max(1e-6)))));
            }
            if let Some(v) = per_channel(ui, "g", m.g, 0.01, 0.999) {
                actions.push(Action::Set(Setting::G(v)));
            }
            let mut eta = m.eta;
            ui.horizontal(|ui| {
                ui.label("η");
                ui.add(egui::DragValue::new(&mut eta).speed(0.01).range(1.0..=3.0).clamp_existing_to_range(false));
            });
            if eta != m.eta {
                actions.push(Action::Set(Setting::Eta(eta)));
            }
        });
        egui::CollapsingHeader::new("Rendering").default_open(true).show(ui, |ui| {
            let mut model = s.model;
            ui.horizontal(|ui| {
                for entry in crate::models::MODELS {
                    ui.radio_value(&mut model, entry.model, entry.label);
                }
            });
            if model != s.model {
                actions.push(Action::Set(Setting::Model(model)));
            }
            let mut epsilon = s.epsilon;
            ui.add(egui::Slider::new(&mut epsilon, 0.005..=1.0).logarithmic(true).clamping(Edits).text("ε"));
            if epsilon != s.epsilon {
                actions.push(Action::Set(Setting::Epsilon(epsilon)));
            }
            // The first translucent object's samples (none where nothing is translucent).
            let mut samples = s.samples;
            if s.material.is_some() {
                let response = ui.add(
                    egui::DragValue::new(&mut samples)
                        .speed(64)
                        .range(2..=1 << 20)
                        .clamp_existing_to_range(false)
                        .prefix("samples "),
                );
                // A new hierarchy per change: only once the drag ends.
                if samples != s.samples && !response.dragged() {
                    actions.push(Action::Set(Setting::Samples(samples)));
                }
            }
            let mut auto = s.exposure.is_none();
            let mut stops = s.exposure.unwrap_or(0.0);
            ui.horizontal(|ui| {
                ui.checkbox(&mut auto, "auto exposure");
                ui.add_enabled(!auto, egui::Slider::new(&mut stops, -8.0..=8.0).clamping(Edits).text("stops"));
            });
            let exposure = (!auto).then_some(stops);
            if exposure != s.exposure {
                actions.push(Action::Set(Setting::Exposure(exposure)));
            }
            let (mut specular, mut roughness) = (s.specular, s.roughness);
            ui.horizontal(|ui| {
                ui.checkbox(&mut specular, "specular");
                ui.add_enabled(
                    specular,
                    egui::Slider::new(&mut roughness, 0.02..=1.0).clamping(Edits).text("roughness"),
                );
            });
            if specular != s.specular {
                actions.push(Action::Set(Setting::Specular(specular)));
            }
            if roughness != s.roughness {
                actions.push(Action::Set(Setting::Roughness(roughness)));
            }
            let mut brute_force = s.brute_force;
            ui.checkbox(&mut brute_force, "brute force (every point, for comparison)");
            if brute_force != s.brute_force {
                actions.push(Action::Set(Setting::BruteForce(brute_force)));
            }
            let mut show = s.show;
            ui.horizontal(|ui| {
                ui.radio_value(&mut show, Show::Shading, "shading");
                ui.radio_value(&mut show, Show::Samples, "samples");
                let level = if let Show::Tree(l) = s.show { l } else { 4 };
                ui.radio_value(&mut show, Show::Tree(level), "tree");
                if let Show::Tree(l) = &mut show {
                    ui.add(egui::DragValue::new(l).range(0..=24).clamp_existing_to_range(false).prefix("level "));
                }
            });
            if show != s.show {
                actions.push(Action::Set(Setting::Show(show)));
            }
            if let Some(playing) = s.playing {
                if ui.button(if playing { "pause" } else { "play" }).clicked() {
                    actions.push(Action::TogglePause);
                }
            }
        });
        lights_and_environment(ui, s, actions);
        egui::CollapsingHeader::new("Timings").default_open(true).show(ui, |ui| {
            ui.label(&s.device);
            ui.label(format!("{} · {:.2} fps", s.last_frame, s.fps));
            if let Some((nodes, points)) = s.work_per_pixel {
                ui.label(format!("{} points · {nodes:.1} nodes, {points:.1} points per pixel", s.samples));
            } else {
                ui.label(format!("{} points (--profile counts the work per pixel)", s.samples));
            }
            if let Some(p) = s.refining {
                ui.add(egui::ProgressBar::new(p).text(format!("refining {:.0}%", 100.0 * p)));
            }
            egui::Grid::new("passes").num_columns(2).striped(true).show(ui, |ui| {
                for (name, ms) in &s.passes {
                    ui.label(name);
                    ui.label(format!("{ms:.1} ms"));
                    ui.end_row();
                }
            });
            ui.label("keys: t writes a trace of 10 frames, p a screenshot, h hides this panel");
        });
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state(material: crate::materials::Material) -> PanelState {
        PanelState {
            material: Some(material),
            model: Model::Directional,
            epsilon: 0.1,
            samples: 4096,
            exposure: None,
            specular: true,
            roughness: 0.35,
            brute_force: false,
            show: Show::Tree(3),
            playing: Some(true),
            device: "test".into(),
            last_frame: "96x96 refined in 1 ms".into(),
            fps: 1.0,
            work_per_pixel: Some((10.0, 2.0)),
            passes: vec![("shade".into(), 1.0)],
            refining: Some(0.5),
            lights: vec![
                Light::Directional { toward: Vec3::new(0.3, 0.8, 0.5), irradiance: Vec3::ONE },
                Light::Point { position: Vec3::new(1.0, 2.0, 3.0), intensity: Vec3::splat(4.0) },
            ],
            environment: Some(EnvironmentState { name: "--env sky".into(), scale: 1.0, rotate_deg: 0.0, samples: 64 }),
        }
    }

    /// Where the panel drew a text containing `needle` (searching egui's output shapes).
    fn text_position(shapes: &[egui::epaint::ClippedShape], needle: &str) -> Option<egui::Pos2> {
        fn find(shape: &egui::Shape, needle: &str) -> Option<egui::Pos2> {
            match shape {
                egui::Shape::Text(t) if t.galley.text().contains(needle) => {
                    Some(t.pos + t.galley.rect.center().to_vec2())
                }
                egui::Shape::Vec(v) => v.iter().find_map(|s| find(s, needle)),
                _ => None,
            }
        }
        shapes.iter().find_map(|c| find(&c.shape, needle))
    }

    #[test]
    fn clicking_the_brute_force_box_asks_for_brute_force() {
        let ctx = egui::Context::default();
        let s = state(crate::materials::Material::find("skin1").unwrap());
        let screen = Some(egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(800.0, 900.0)));
        let frame = |events: Vec<egui::Event>| {
            let mut actions = Vec::new();
            let input = egui::RawInput { screen_rect: screen, events, ..Default::default() };
            let output = ctx.run_ui(input, |ui| draw(ui.ctx(), &s, &mut actions));
            (output, actions)
        };
        // egui lays a new window out over a first, invisible pass.
        frame(Vec::new());
        let (output, _) = frame(Vec::new());
        let at = text_position(&output.shapes, "brute force").expect("the brute force box is drawn");
        let button = |pressed| egui::Event::PointerButton {
            pos: at,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: Default::default(),
        };
        frame(vec![egui::Event::PointerMoved(at), button(true)]);
        let (_, actions) = frame(vec![button(false)]);
        assert_eq!(actions, vec![Action::Set(Setting::BruteForce(true))]);
    }

    /// Opening the lights and clicking "add point" adds a point light; opening the environment
    /// and clicking "off" removes it.
    #[test]
    fn the_panel_adds_lights_and_turns_the_environment_off() {
        let ctx = egui::Context::default();
        let s = state(crate::materials::Material::find("skin1").unwrap());
        let screen = Some(egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(800.0, 1400.0)));
        // Time moves on 0.3 s a frame: a section's opening animation (1/12 s) ends at once and a
        // press and release still make a click (within 0.8 s).
        let clock = std::cell::Cell::new(0.0);
        let frame = |events: Vec<egui::Event>| {
            let mut actions = Vec::new();
            clock.set(clock.get() + 0.3);
            let input = egui::RawInput { screen_rect: screen, events, time: Some(clock.get()), ..Default::default() };
            let output = ctx.run_ui(input, |ui| draw(ui.ctx(), &s, &mut actions));
            (output, actions)
        };
        let click = |needle: &str| {
            let (output, _) = frame(Vec::new());
            let at = text_position(&output.shapes, needle).unwrap_or_else(|| panic!("{needle} is drawn"));
            let button = |pressed| egui::Event::PointerButton {
                pos: at,
                button: egui::PointerButton::Primary,
                pressed,
                modifiers: Default::default(),
            };
            frame(vec![egui::Event::PointerMoved(at), button(true)]);
            let (_, actions) = frame(vec![button(false)]);
            frame(vec![egui::Event::PointerGone]);
            actions
        };
        frame(Vec::new());
        assert!(click("Lights").is_empty(), "opening a section changes nothing");
        assert_eq!(
            click("add point"),
            vec![Action::AddLight(Light::Point { position: Vec3::new(0.0, 2.0, 2.0), intensity: Vec3::splat(4.0) })]
        );
        assert!(click("Environment").is_empty());
        assert_eq!(click("off"), vec![Action::Environment(EnvEdit::Map(None))]);
    }

    #[test]
    fn an_untouched_panel_changes_nothing() {
        // A spurious action (a value rounded or clamped by a widget) would re-render forever.
        let ctx = egui::Context::default();
        let mut unusual = state(crate::materials::Material::find("marble").unwrap());
        // Values the widgets' ranges do not cover, as the command line may set them.
        (unusual.epsilon, unusual.roughness, unusual.exposure, unusual.samples) = (0.0, 0.01, Some(12.0), 1 << 21);
        unusual.show = Show::Tree(40);
        unusual.material.as_mut().unwrap().eta = 0.8;
        // Nothing translucent: no material, no samples.
        let mut opaque_only = state(crate::materials::Material::find("marble").unwrap());
        (opaque_only.material, opaque_only.samples) = (None, 0);
        let states = crate::materials::Material::presets().into_iter().map(state).chain([unusual, opaque_only]);
        for s in states {
            let name = s.material.as_ref().map_or("no material".to_string(), |m| m.name.clone());
            for _ in 0..3 {
                let mut actions = Vec::new();
                let input = egui::RawInput {
                    screen_rect: Some(egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(800.0, 900.0))),
                    ..Default::default()
                };
                let _ = ctx.run_ui(input, |ui| draw(ui.ctx(), &s, &mut actions));
                assert!(actions.is_empty(), "{name}: {actions:?}");
            }
        }
    }
}
