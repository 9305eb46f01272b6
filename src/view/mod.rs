//! `translucent view`: the renderer's frames in a window, with an orbit camera, light and material
//! edits from the mouse, the keys or a `--script`, scripted frame counts and screenshots.
//!
//! In three parts: this file, the window and its input turned into actions (and carrying out the
//! schedule's plan); `schedule.rs`, when to render what (pure, unit-tested); `state.rs`, the world
//! and frame description that actions edit, by one route. The frame is the same
//! `Renderer::begin_frame` / `shade_some` / `finish_frame` as `render` and the tests; its
//! tone-mapped image is copied into an image that the presenter blits to the window
//! (src/vk/swapchain.rs).

pub mod controls;
mod panel;
pub mod schedule;
pub mod state;

use std::collections::VecDeque;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, ModifiersState, NamedKey};
use winit::raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use winit::window::{Window, WindowId};

use crate::cli::ViewArgs;
use crate::error::{Error, Result};
use crate::frame::{FrameInProgress, Renderer};
use crate::frame_desc::Show;
use crate::profiling::ProfileReport;
use crate::settings::{RenderSettings, SceneSettings};
use crate::vk::{self, Context, Image, ImageUsageFlags, Presented, Presenter, TimedScope};
use crate::{bad_input, runtime};
use controls::{Action, Drag, ScriptLine, Setting};
use schedule::{FrameKind, Schedule, Turn, STEP_BUDGET};
use state::{Applied, ViewState};

/// Whether the environment names a window system at all (X11 or Wayland).
fn has_window_system() -> bool {
    ["DISPLAY", "WAYLAND_DISPLAY", "WAYLAND_SOCKET"].iter().any(|v| std::env::var_os(v).is_some_and(|s| !s.is_empty()))
}

fn no_window_system(why: &str) -> Error {
    bad_input!(
        "view needs a window system ({why}); `translucent render` writes images without one (or run `xvfb-run -a translucent view …`)"
    )
}

/// Whether `--frames` was given (its default of 1 is `render`'s; `view` runs until closed without it).
fn frames_given() -> bool {
    std::env::args_os().any(|a| {
        let a = a.to_string_lossy();
        a == "--frames" || a.starts_with("--frames=")
    })
}

pub fn run(args: &ViewArgs) -> Result<i32> {
    // Everything the user typed is checked before a window opens.
    if let Some(p) = &args.screenshot {
        controls::parse_line(&format!("screenshot {}", p.display())).map_err(|e| bad_input!("--screenshot {e}"))?;
    }
    let script = match &args.script {
        Some(p) => controls::load_script(p)?,
        None => Vec::new(),
    };
    // A scene file (`view SCENE.pbrt`, `view SCENE.gltf`) as `render` reads it: its film (or camera) sizes the window.
    let from_scene;
    let (args, settings) = match &args.render.scene {
        Some(scene) => {
            let argv: Vec<String> = std::env::args().collect();
            let (render, settings) =
                crate::settings::scene_file_settings(scene, &args.render, &|f| crate::pbrt::flag_given(&argv, f))?;
            from_scene = ViewArgs { render, ..args.clone() };
            (&from_scene, settings)
        }
        None => (args, RenderSettings::from_args(&args.render)?),
    };
    if !has_window_system() {
        return Err(no_window_system("neither DISPLAY nor WAYLAND_DISPLAY is set"));
    }
    let event_loop = EventLoop::new().map_err(|e| no_window_system(&format!("cannot connect: {e}")))?;
    let mut app = App {
        args,
        start: Some(settings),
        viewer: None,
        error: None,
        validation: None,
        script: script.into(),
        frames_limit: frames_given().then_some(args.render.frames),
    };
    event_loop.run_app(&mut app).map_err(|e| runtime!("window event loop: {e}"))?;
    let App { viewer, error, validation, .. } = app;
    // Presenter before renderer (device) before window: see Viewer's field order.
    drop(viewer);
    if let Some(e) = error {
        return Err(e);
    }
    Ok(match validation {
        Some((validating, counts)) => counts.exit_code(validating),
        None => 0,
    })
}

struct App<'a> {
    args: &'a ViewArgs,
    /// What the viewer is built from, taken when the window opens.
    start: Option<RenderSettings>,
    viewer: Option<Viewer>,
    error: Option<Error>,
    validation: Option<(bool, Arc<vk::ValidationCounts>)>,
    script: VecDeque<ScriptLine>,
    frames_limit: Option<u32>,
}

impl App<'_> {
    fn fail(&mut self, event_loop: &ActiveEventLoop, e: Error) {
        if self.error.is_none() {
            self.error = Some(e);
        }
        event_loop.exit();
    }
}

impl ApplicationHandler for App<'_> {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        let Some(settings) = self.start.take() else { return };
        let script = std::mem::take(&mut self.script);
        match Viewer::new(event_loop, self.args, settings, script, self.frames_limit) {
            Ok(viewer) => {
                self.validation = Some((viewer.renderer.ctx.validation, viewer.renderer.ctx.validation_counts()));
                self.viewer = Some(viewer);
            }
            Err(e) => self.fail(event_loop, e),
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let Some(viewer) = self.viewer.as_mut() else { return };
        // The panel sees every event first; what it takes (a click on it, typing into it) goes no
        // further, except cursor positions, which the drags need to stay continuous.
        let mut consumed = false;
        if let Some(ui) = viewer.ui.as_mut().filter(|ui| ui.shown) {
            let response = ui.state.on_window_event(&viewer.window, &event);
            if response.repaint {
                viewer.ui_repaint = true;
            }
            consumed = response.consumed && !matches!(event, WindowEvent::CursorMoved { .. });
        }
        let result = match event {
            WindowEvent::MouseInput { state, button, .. } if consumed => {
                if state == ElementState::Released {
                    viewer.input.buttons.retain(|b| *b != button);
                }
                Ok(())
            }
            WindowEvent::MouseWheel { .. } | WindowEvent::KeyboardInput { .. } if consumed => Ok(()),
            WindowEvent::CloseRequested => {
                viewer.quit = true;
                Ok(())
            }
            WindowEvent::Resized(size) => {
                viewer.resized(size.width, size.height);
                Ok(())
            }
            WindowEvent::RedrawRequested => {
                let started = Instant::now();
                let result = viewer.step();
                viewer.longest_turn = viewer.longest_turn.max(started.elapsed());
                viewer.longest_turn_of_frame = viewer.longest_turn_of_frame.max(started.elapsed());
                result
            }
            WindowEvent::ModifiersChanged(m) => {
                viewer.input.modifiers = m.state();
                Ok(())
            }
            WindowEvent::MouseInput { state, button, .. } => {
                viewer.input.buttons.retain(|b| *b != button);
                if state == ElementState::Pressed {
                    viewer.input.buttons.push(button);
                }
                Ok(())
            }
            WindowEvent::CursorMoved { position, .. } => {
                viewer.cursor_moved(position.x, position.y);
                Ok(())
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let notches = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                viewer.interact(Action::Zoom(1.1f32.powf(notches)))
            }
            WindowEvent::KeyboardInput { event, .. } if event.state == ElementState::Pressed => {
                viewer.key(&event.logical_key)
            }
            _ => Ok(()),
        };
        if let Err(e) = result {
            self.fail(event_loop, e);
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        let Some(viewer) = self.viewer.as_mut() else { return };
        if viewer.quit {
            if let Err(e) = viewer.finish() {
                self.fail(event_loop, e);
            }
            event_loop.exit();
            return;
        }
        match viewer.next_turn() {
            Turn::Now => {
                event_loop.set_control_flow(ControlFlow::Poll);
                viewer.window.request_redraw();
            }
            Turn::At(when) => event_loop.set_control_flow(ControlFlow::WaitUntil(when)),
            Turn::OnInput => event_loop.set_control_flow(ControlFlow::Wait),
        }
    }
}

/// The first tile side on a CPU device: a 64×64 tile of the default scene shades in about 15 ms
/// on lavapipe (2 cores), well inside STEP_BUDGET, and each tile is a draw of its own, so smaller
/// tiles would spend the frame on draws (tiles of 16 took twice the shading time of one draw).
const CPU_TILE: u32 = 64;

/// The renderer's shading submissions in the window: short, to fit STEP_BUDGET.
const SUBMISSION_TARGET_S: f64 = 0.04;

/// How long a scripted resize waits for the window system before going on with the size it has.
const RESIZE_WAIT: Duration = Duration::from_secs(3);

#[derive(Default)]
struct Input {
    buttons: Vec<MouseButton>,
    modifiers: ModifiersState,
    cursor: Option<(f64, f64)>,
}

/// Degrees of orbit per pixel dragged.
const DEGREES_PER_PIXEL: f32 = 0.4;

/// The panel: egui's input state and its renderer over the swapchain image.
struct Ui {
    state: egui_winit::State,
    overlay: vk::Overlay,
    shown: bool,
}

/// The last frames' numbers, for the panel.
#[derive(Default)]
struct PanelNumbers {
    device: String,
    last_frame: String,
    fps: f64,
    work_per_pixel: Option<(f64, f64)>,
    passes: Vec<(String, f64)>,
    refining: Option<f32>,
}

fn panel_state(
    numbers: &PanelNumbers,
    view: &ViewState,
    renderer: &Renderer,
    exposure: Option<f32>,
    playing: Option<bool>,
) -> panel::PanelState {
    let d = &view.desc;
    panel::PanelState {
        material: view.material().cloned(),
        model: d.integration.model,
        epsilon: d.integration.epsilon,
        samples: view.world.objects.first().and_then(|o| o.samples).or(renderer.point_count()).unwrap_or(0),
        exposure,
        specular: d.specular,
        roughness: d.roughness,
        brute_force: d.integration.brute_force,
        show: d.show,
        playing,
        device: numbers.device.clone(),
        last_frame: numbers.last_frame.clone(),
        fps: numbers.fps,
        work_per_pixel: numbers.work_per_pixel,
        passes: numbers.passes.clone(),
        refining: numbers.refining,
        lights: view.own_lights().to_vec(),
        environment: d.environment.as_ref().map(|e| panel::EnvironmentState {
            name: e.name.clone(),
            scale: e.scale,
            rotate_deg: view.env_rotate_deg,
            samples: e.samples,
        }),
    }
}

struct Viewer {
    // Field order is drop order: the image, panel and presenter (surface) before the renderer
    // (which owns the device), the window last.
    /// The tone-mapped image in the swapchain's 8-bit encoding, blitted to the window.
    source: Option<Image>,
    /// The panel, when shown.
    ui: Option<Ui>,
    presenter: Presenter,
    renderer: Renderer,
    window: Arc<Window>,
    /// What is shown, and the one route by which actions edit it.
    view: ViewState,
    /// When to render what.
    schedule: Schedule,
    /// The window's size in pixels (zero when minimised).
    size: (u32, u32),
    script: VecDeque<ScriptLine>,
    /// Frames the current script line still waits for.
    script_frames: u32,
    /// A scripted resize not yet applied by the window system, and when it was asked for.
    pending_resize: Option<((u32, u32), Instant)>,
    /// Exit after this many presented frames (`--frames`).
    frames_limit: Option<u32>,
    presented: u32,
    /// A rendered frame has not reached the window yet (skipped present, or never shown).
    unshown: bool,
    quit: bool,
    input: Input,
    screenshot_at_exit: Option<PathBuf>,
    /// Chrome trace being collected: frames still to take, the frames so far, the file.
    trace: Option<(u32, Vec<Vec<TimedScope>>, PathBuf)>,
    fps: FrameClock,
    device_name: String,
    /// The frame being shaded over turns of the loop, what it is, and when it was begun.
    frame: Option<(FrameInProgress, FrameKind, Instant)>,
    /// A mesh sequence or deformation, and the step shown.
    animation: Option<crate::deform::Animation>,
    animation_frame: u32,
    /// The panel asked to be drawn again.
    ui_repaint: bool,
    /// Changes made on the panel, applied at the start of the next turn.
    pending_actions: Vec<Action>,
    /// The numbers the panel shows about the last frames.
    panel_numbers: PanelNumbers,
    /// The longest turn of the event loop spent in the viewer (reported at exit).
    longest_turn: Duration,
    /// The same since the last frame was shown.
    longest_turn_of_frame: Duration,
}

/// Frame times for the title bar.
struct FrameClock {
    last: Option<Instant>,
    seconds: f64,
}

impl Viewer {
    fn new(
        event_loop: &ActiveEventLoop,
        args: &ViewArgs,
        settings: RenderSettings,
        script: VecDeque<ScriptLine>,
        frames_limit: Option<u32>,
    ) -> Result<Viewer> {
        let r = &args.render;
        let attributes = Window::default_attributes()
            .with_title("translucent")
            .with_inner_size(PhysicalSize::new(r.width, r.height));
        let window =
            Arc::new(event_loop.create_window(attributes).map_err(|e| no_window_system(&format!("no window: {e}")))?);
        let display = event_loop.display_handle().map_err(|e| runtime!("display handle: {e}"))?.as_raw();
        let ctx = Context::for_window(&r.device.options(), display)?;
        let device_name = format!("{} ({})", ctx.info.name, ctx.info.driver);
        let size = window.inner_size();
        let handle = window.window_handle().map_err(|e| runtime!("window handle: {e}"))?.as_raw();
        let presenter = Presenter::new(&ctx, display, handle, (size.width, size.height), args.present_mode.into())?;
        log::info!("window {}x{}, swapchain format {:?}", size.width, size.height, presenter.surface_format());

        let RenderSettings { world, mut desc, profile } = settings;
        // The window's size: frames follow it from the first on.
        (desc.width, desc.height) = (size.width.max(1), size.height.max(1));
        let mut renderer = Renderer::new(ctx, profile)?;
        renderer.set_submission_target(SUBMISSION_TARGET_S);
        if renderer.ctx.info.device_type == ash::vk::PhysicalDeviceType::CPU {
            // A CPU device (lavapipe) takes most of a second per frame: tiles small enough for a
            // turn of the event loop from the first frame on (they adapt further, see MIN_TILE).
            renderer.set_tile_size(CPU_TILE);
        }
        let device_label = device_name.clone();
        let mesh_spec = SceneSettings::from_args(r).mesh_spec();
        // The first translucent object is the one animated (none in a world of opaque objects).
        let animation = match world.objects.first() {
            Some(o) => crate::deform::Animation::new(&mesh_spec, &o.mesh, r.deform, r.deform_period, r.up)?,
            None if r.deform.is_some() => return Err(bad_input!("--deform: the scene has no translucent object")),
            None => None,
        };
        let ui = if args.no_panel {
            None
        } else {
            let egui_ctx = egui::Context::default();
            let state = egui_winit::State::new(
                egui_ctx,
                egui::ViewportId::ROOT,
                &window,
                Some(window.scale_factor() as f32),
                None,
                Some(renderer.ctx.limits().max_image_dimension2_d as usize),
            );
            let overlay = vk::Overlay::new(&renderer.ctx, presenter.surface_format())?;
            Some(Ui { state, overlay, shown: true })
        };
        Ok(Viewer {
            source: None,
            presenter,
            renderer,
            window,
            // From flags the environment's frame is --env-rotate's rotation (`env rotate` sets
            // it again); a scene's is its light's transform.
            view: match r.scene {
                None => ViewState::new(world, desc).with_env_rotation(r.env_rotate),
                Some(_) => ViewState::new(world, desc),
            },
            schedule: Schedule::default(),
            size: (size.width, size.height),
            script,
            script_frames: 0,
            pending_resize: None,
            frames_limit,
            presented: 0,
            unshown: false,
            quit: false,
            input: Input::default(),
            screenshot_at_exit: args.screenshot.clone(),
            trace: None,
            fps: FrameClock { last: None, seconds: 0.0 },
            device_name,
            frame: None,
            animation,
            animation_frame: 0,
            ui,
            ui_repaint: true,
            pending_actions: Vec::new(),
            panel_numbers: PanelNumbers { device: device_label, ..Default::default() },
            longest_turn: Duration::ZERO,
            longest_turn_of_frame: Duration::ZERO,
        })
    }

    /// Whether a new frame is asked for (not counting the refinement of a preview).
    fn new_frame_wanted(&self) -> bool {
        let limit_left = self.frames_limit.is_some_and(|n| self.presented < n);
        let playing = self.view.playing && self.animation.is_some();
        self.schedule.is_dirty() || self.script_frames > 0 || limit_left || self.trace.is_some() || playing
    }

    /// When the loop should come round again.
    fn next_turn(&self) -> Turn {
        if let Some((_, asked)) = self.pending_resize {
            // Waiting for the window system to apply a scripted resize: look again shortly.
            return if asked.elapsed() > RESIZE_WAIT {
                Turn::Now
            } else {
                Turn::At(Instant::now() + Duration::from_millis(20))
            };
        }
        if self.minimised() {
            return if self.script_frames > 0 || !self.script.is_empty() { Turn::Now } else { Turn::OnInput };
        }
        if self.new_frame_wanted()
            || self.frame.is_some()
            || self.unshown
            || self.ui_repaint
            || !self.pending_actions.is_empty()
            || !self.script.is_empty()
        {
            return Turn::Now;
        }
        self.schedule.idle_turn(Instant::now())
    }

    fn minimised(&self) -> bool {
        self.size.0 == 0 || self.size.1 == 0
    }

    /// The window's new size, from the window system or a scripted resize (zero: minimised).
    fn resized(&mut self, width: u32, height: u32) {
        if (width, height) != self.size {
            self.size = (width, height);
            self.presenter.resize(width, height);
            if !self.minimised() {
                self.schedule.changed();
            }
        }
        if self.pending_resize.is_some_and(|(want, _)| want == (width, height)) {
            self.pending_resize = None;
        }
    }

    fn cursor_moved(&mut self, x: f64, y: f64) {
        let previous = self.input.cursor.replace((x, y));
        let Some((px, py)) = previous else { return };
        let (dx, dy) = ((x - px) as f32, (y - py) as f32);
        let (b, m) = (&self.input.buttons, self.input.modifiers);
        let kind = if b.contains(&MouseButton::Left) && m.control_key() {
            Drag::Light
        } else if b.contains(&MouseButton::Middle)
            || b.contains(&MouseButton::Right)
            || (b.contains(&MouseButton::Left) && m.shift_key())
        {
            Drag::Pan
        } else if b.contains(&MouseButton::Left) {
            Drag::Orbit
        } else {
            return;
        };
        if let Err(e) = self.drag(kind, dx, dy) {
            log::error!("{e}");
        }
    }

    /// A mouse drag of `dx`, `dy` pixels, from the mouse or a script's `drag` line.
    fn drag(&mut self, kind: Drag, dx: f32, dy: f32) -> Result<()> {
        let action = match kind {
            Drag::Light => Action::TurnLights { right_deg: dx * DEGREES_PER_PIXEL, up_deg: -dy * DEGREES_PER_PIXEL },
            Drag::Pan => {
                let h = self.size.1.max(1) as f32;
                Action::Pan { right: -dx / h, up: dy / h }
            }
            Drag::Orbit => Action::Orbit { right_deg: -dx * DEGREES_PER_PIXEL, up_deg: dy * DEGREES_PER_PIXEL },
        };
        self.interact(action)
    }

    fn key(&mut self, key: &Key) -> Result<()> {
        let shift = self.input.modifiers.shift_key();
        let d = &self.view.desc;
        let step = 5.0;
        let action = match key {
            Key::Named(NamedKey::Escape) => Action::Quit,
            Key::Named(NamedKey::ArrowLeft) if shift => Action::Pan { right: -0.05, up: 0.0 },
            Key::Named(NamedKey::ArrowRight) if shift => Action::Pan { right: 0.05, up: 0.0 },
            Key::Named(NamedKey::ArrowUp) if shift => Action::Pan { right: 0.0, up: 0.05 },
            Key::Named(NamedKey::ArrowDown) if shift => Action::Pan { right: 0.0, up: -0.05 },
            Key::Named(NamedKey::ArrowLeft) => Action::Orbit { right_deg: -step, up_deg: 0.0 },
            Key::Named(NamedKey::ArrowRight) => Action::Orbit { right_deg: step, up_deg: 0.0 },
            Key::Named(NamedKey::ArrowUp) => Action::Orbit { right_deg: 0.0, up_deg: step },
            Key::Named(NamedKey::ArrowDown) => Action::Orbit { right_deg: 0.0, up_deg: -step },
            Key::Named(NamedKey::Space) => Action::TogglePause,
            Key::Character(c) => match c.as_str() {
                "q" => Action::Quit,
                "+" | "=" => Action::Zoom(1.1),
                "-" => Action::Zoom(1.0 / 1.1),
                "j" => Action::TurnLights { right_deg: -step, up_deg: 0.0 },
                "l" => Action::TurnLights { right_deg: step, up_deg: 0.0 },
                "i" => Action::TurnLights { right_deg: 0.0, up_deg: step },
                "k" => Action::TurnLights { right_deg: 0.0, up_deg: -step },
                "p" => Action::Screenshot(next_free_path("translucent-view", "png")),
                "h" => {
                    if let Some(ui) = self.ui.as_mut() {
                        ui.shown = !ui.shown;
                        self.ui_repaint = true;
                    }
                    return Ok(());
                }
                // The panel's settings, from the keys.
                "m" => {
                    let presets = crate::materials::Material::presets();
                    let name = self.view.material().map(|m| m.name.clone());
                    let now = presets.iter().position(|m| Some(&m.name) == name.as_ref()).unwrap_or(0);
                    Action::Material(
                        presets[(now + if shift { presets.len() - 1 } else { 1 }) % presets.len()].name.clone(),
                    )
                }
                "d" => Action::Set(Setting::Model(d.integration.model.next())),
                "b" => Action::Set(Setting::BruteForce(!d.integration.brute_force)),
                "s" => Action::Set(Setting::Specular(!d.specular)),
                "[" => Action::Set(Setting::Epsilon(d.integration.epsilon / 2.0)),
                "]" => Action::Set(Setting::Epsilon((d.integration.epsilon * 2.0).max(1e-3))),
                "," => Action::Set(Setting::Exposure(Some(self.view.exposure_stops - 0.5))),
                "." => Action::Set(Setting::Exposure(Some(self.view.exposure_stops + 0.5))),
                "v" => Action::Set(Setting::Show(match d.show {
                    Show::Shading => Show::Samples,
                    Show::Samples => Show::Tree(2),
                    Show::Tree(l) if l < 8 => Show::Tree(l + 2),
                    Show::Tree(_) => Show::Shading,
                })),
                "t" => Action::Trace(10, next_free_path("translucent-trace", "json")),
                _ => return Ok(()),
            },
            _ => return Ok(()),
        };
        self.interact(action)
    }

    /// An action from the mouse or the keys: frames are previews while these keep coming.
    fn interact(&mut self, action: Action) -> Result<()> {
        self.schedule.interacted(Instant::now());
        self.apply(action)
    }

    /// Applies one action: what is drawn changes through [`ViewState::apply`] alone; the rest is
    /// the window's.
    fn apply(&mut self, action: Action) -> Result<()> {
        let action = match self.view.apply(action)? {
            Applied::Edited => {
                self.schedule.changed();
                return Ok(());
            }
            Applied::Window(action) => action,
        };
        match action {
            Action::Frames(n) => self.script_frames = n,
            Action::Drag(kind, dx, dy) => self.drag(kind, dx, dy)?,
            Action::Screenshot(path) => {
                self.refine_now()?;
                self.renderer.write_image(&path)?;
                eprintln!("wrote {}", path.display());
            }
            Action::Resize(0, 0) => {
                // Not every window system can minimise (X without a window manager cannot), so
                // the zero size goes through the same path as the window system's own event.
                self.window.set_minimized(true);
                self.resized(0, 0);
            }
            Action::Resize(w, h) => {
                if self.minimised() {
                    self.window.set_minimized(false);
                }
                let now = self.window.inner_size();
                if (now.width, now.height) == (w, h) {
                    self.resized(w, h);
                } else {
                    self.pending_resize = Some(((w, h), Instant::now()));
                    if let Some(applied) = self.window.request_inner_size(PhysicalSize::new(w, h)) {
                        self.resized(applied.width, applied.height);
                    }
                }
            }
            Action::Trace(frames, path) => {
                self.trace = Some((frames, Vec::new(), path));
                self.schedule.changed();
            }
            Action::Quit => self.quit = true,
            // Edits: ViewState::apply took them.
            _ => {}
        }
        Ok(())
    }

    /// Makes sure that the last frame shown is the current scene at the window's size.
    fn refine_now(&mut self) -> Result<()> {
        if self.schedule.is_dirty() || matches!(self.frame, Some((_, FrameKind::Preview, _))) {
            self.frame = None;
            self.schedule.dropped();
        }
        if self.frame.is_none() && (self.schedule.is_dirty() || self.schedule.shown_preview() || self.source.is_none())
        {
            self.begin(FrameKind::Full)?;
        }
        if self.frame.is_some() {
            self.shade(None)?;
        }
        Ok(())
    }

    /// Runs script lines until one has to wait (for frames or a resize).
    fn run_script(&mut self) -> Result<()> {
        if let Some((want, asked)) = self.pending_resize {
            if asked.elapsed() < RESIZE_WAIT {
                return Ok(());
            }
            let now = self.window.inner_size();
            log::warn!("resize {}x{}: the window system gave {}x{}", want.0, want.1, now.width, now.height);
            self.pending_resize = None;
            self.resized(now.width, now.height);
        }
        while self.script_frames == 0 && self.pending_resize.is_none() && !self.quit {
            let Some(line) = self.script.pop_front() else { break };
            log::info!("script line {}: {}", line.number, line.text);
            self.apply(line.action).map_err(|e| match e {
                Error::BadInput(m) => bad_input!("--script line {} (`{}`): {m}", line.number, line.text),
                Error::Runtime(m) => runtime!("--script line {} (`{}`): {m}", line.number, line.text),
            })?;
        }
        Ok(())
    }

    /// One turn of the loop: script lines, then a step of a frame (a preview or a full one), or a
    /// present of the last frame.
    fn step(&mut self) -> Result<()> {
        // The panel's changes of the last present, for this frame. One it refuses is reported
        // and left out; the viewer goes on.
        for action in std::mem::take(&mut self.pending_actions) {
            if let Err(e) = self.apply(action) {
                eprintln!("warning: panel: {e}");
            }
        }
        self.run_script()?;
        if self.quit {
            return Ok(());
        }
        if self.minimised() {
            // Nothing to show; a scripted frame count still runs down so the script goes on.
            self.script_frames = self.script_frames.saturating_sub(1);
            return Ok(());
        }
        let plan = self.schedule.plan(Instant::now(), self.new_frame_wanted());
        if plan.drop {
            // A full frame of an old view is dropped; a preview is short and is finished.
            self.frame = None;
            self.schedule.dropped();
        }
        if let Some(kind) = plan.begin {
            self.begin(kind)?;
        }
        if self.frame.is_some() {
            let finished = self.shade(Some(STEP_BUDGET))?;
            if !finished && self.ui_repaint && !self.unshown {
                // The panel stays live while a frame is refined: the last image again, new panel.
                self.present()?;
            }
        } else if self.unshown || self.source.is_some() {
            // Exposed or skipped: show the last frame again without rendering it again.
            self.present()?;
        }
        if self.frames_limit.is_some_and(|n| self.presented >= n) {
            self.quit = true;
        }
        Ok(())
    }

    /// Starts a frame of the current view: the window's size, or a fraction of it for a preview.
    fn begin(&mut self, kind: FrameKind) -> Result<()> {
        let started = Instant::now();
        if let Some(animation) = self.animation.as_ref().filter(|_| self.view.playing) {
            // This step of the sequence or deformation (normals recomputed); the next frame shows
            // the next.
            self.view.world.objects[0].mesh = animation.mesh(self.animation_frame)?;
            self.animation_frame += 1;
        }
        // The frame is of the window's size, or a fraction of it for a preview.
        let mut desc = self.view.desc.clone();
        (desc.width, desc.height) = self.schedule.frame_size(kind, self.size);
        let frame = self.renderer.begin_frame(&self.view.world, &desc)?;
        log::debug!("{kind:?} frame begun (hierarchy, depth) in {:.0} ms", started.elapsed().as_secs_f64() * 1e3);
        self.frame = Some((frame, kind, started));
        self.schedule.begun(kind);
        Ok(())
    }

    /// Shades the frame in progress for about `budget` (to the end without one); a finished frame
    /// is shown. Returns whether it finished.
    fn shade(&mut self, budget: Option<Duration>) -> Result<bool> {
        let (frame, kind, started) = self.frame.as_mut().expect("a frame in progress");
        let (kind, started) = (*kind, *started);
        let step = Instant::now();
        let shaded = self.renderer.shade_some(frame, budget)?;
        log::debug!("shading step {:.0} ms, {:.0}% done", step.elapsed().as_secs_f64() * 1e3, 100.0 * frame.progress());
        if !shaded {
            if kind == FrameKind::Full {
                self.panel_numbers.refining = Some(frame.progress());
                self.ui_repaint = true;
                let (w, h) = self.size;
                self.window.set_title(&format!(
                    "translucent — {} — {w}x{h} refining {:.0}%",
                    self.device_name,
                    100.0 * frame.progress()
                ));
            }
            return Ok(false);
        }
        let (frame, _, _) = self.frame.take().expect("in progress");
        // One tile longer than a turn's budget: smaller tiles from the next frame on (not on a
        // device that shades whole frames in one go).
        if let Some(tile) = schedule::next_tile(self.renderer.tile_size(), frame.longest_unit_seconds()) {
            self.renderer.set_tile_size(tile);
            log::info!("tiles of {tile} pixels, so that one takes under {} ms", STEP_BUDGET.as_millis());
        }
        let scopes = self.renderer.finish_frame(frame)?;
        let seconds = started.elapsed().as_secs_f64();
        self.schedule.finished(seconds);
        self.frame_rendered(scopes, kind.name(), seconds)?;
        self.present()?;
        Ok(true)
    }

    /// Bookkeeping of a rendered frame: the trace, the frame clock, the title.
    fn frame_rendered(&mut self, scopes: Vec<TimedScope>, kind: &str, seconds: f64) -> Result<()> {
        self.unshown = true;
        if let Some((left, frames, path)) = self.trace.as_mut() {
            frames.push(scopes.clone());
            *left -= 1;
            if *left == 0 {
                let report = ProfileReport::from_frames(&self.device_name, std::mem::take(frames));
                std::fs::write(&*path, crate::profiling::chrome_trace_json(&report))
                    .map_err(|e| runtime!("trace {}: {e}", path.display()))?;
                eprintln!("wrote {} ({} frames)", path.display(), report.frames.len());
                self.trace = None;
            }
        }
        // The frame's GPU time: from its first timestamp to its last.
        let gpu_ms = match (scopes.first(), scopes.last()) {
            (Some(a), Some(b)) => (b.end_ns - a.begin_ns) / 1e6,
            _ => 0.0,
        };
        let now = Instant::now();
        if let Some(last) = self.fps.last.replace(now) {
            self.fps.seconds = (now - last).as_secs_f64();
        }
        let extent = self.renderer.extent();
        let points = self.renderer.point_count().unwrap_or(0);
        let work = self.renderer.work()?;
        let per_pixel = if work.pixels > 0 {
            let px = work.pixels as f64;
            format!(", {:.1} nodes and {:.1} points per pixel", work.node_sum as f64 / px, work.point_sum as f64 / px)
        } else {
            String::new()
        };
        self.window.set_title(&format!(
            "translucent — {} — {}x{} {kind} in {:.0} ms (GPU {gpu_ms:.0} ms), {:.1} fps — {points} points{per_pixel}",
            self.device_name,
            extent.width,
            extent.height,
            seconds * 1e3,
            if self.fps.seconds > 0.0 { 1.0 / self.fps.seconds } else { 0.0 },
        ));
        self.panel_numbers.last_frame = format!("{}x{} {kind} in {:.0} ms", extent.width, extent.height, seconds * 1e3);
        self.panel_numbers.fps = if self.fps.seconds > 0.0 { 1.0 / self.fps.seconds } else { 0.0 };
        self.panel_numbers.work_per_pixel = (work.pixels > 0)
            .then(|| (work.node_sum as f64 / work.pixels as f64, work.point_sum as f64 / work.pixels as f64));
        self.panel_numbers.refining = None;
        if kind == FrameKind::Full.name() {
            self.panel_numbers.passes = pass_list(&scopes);
            // The per-pass GPU times of every full frame, as `render` prints them per run.
            println!(
                "frame {} {}x{} in {:.0} ms, {points} points{per_pixel}: {}",
                self.presented + 1,
                extent.width,
                extent.height,
                seconds * 1e3,
                pass_times(&scopes)
            );
        }
        log::info!(
            "{kind} frame {}x{} in {:.0} ms (GPU {gpu_ms:.0} ms), {:.0} ms since the last shown; longest turn {:.0} ms",
            extent.width,
            extent.height,
            seconds * 1e3,
            self.fps.seconds * 1e3,
            self.longest_turn_of_frame.as_secs_f64() * 1e3
        );
        self.longest_turn_of_frame = Duration::ZERO;
        Ok(())
    }

    /// Shows the last finished frame (copied into the window's image once) with the panel.
    fn present(&mut self) -> Result<()> {
        let ctx = &self.renderer.ctx;
        let fresh = self.unshown;
        if fresh {
            let extent = self.renderer.extent();
            if self.source.as_ref().is_none_or(|s| s.extent != extent) {
                // The previous image may still be read by a present in flight.
                ctx.wait_idle()?;
                self.source = Some(Image::new_2d(
                    ctx,
                    "window image",
                    self.presenter.source_format(),
                    extent,
                    1,
                    // SAMPLED only because every Image has a view, which needs a usage views allow.
                    ImageUsageFlags::TRANSFER_DST | ImageUsageFlags::TRANSFER_SRC | ImageUsageFlags::SAMPLED,
                )?);
            }
        }
        let Some(source) = self.source.as_ref() else { return Ok(()) };
        let ldr = self.renderer.tone_mapped_buffer();
        // The tone-mapped buffer is copied once per finished frame: while the next is in progress
        // it may be of another size.
        let copy = |rec: &mut vk::Recorder| if fresh { rec.copy_buffer_to_image(ldr, source) } else { Ok(()) };
        let playing = self.animation.as_ref().map(|_| self.view.playing);
        let exposure = match self.view.desc.exposure {
            crate::output::Exposure::Stops(s) => Some(s),
            crate::output::Exposure::Auto => None,
        };
        let shown = match self.ui.as_mut().filter(|ui| ui.shown) {
            Some(ui) => {
                let state = panel_state(&self.panel_numbers, &self.view, &self.renderer, exposure, playing);
                let input = ui.state.take_egui_input(&self.window);
                let mut actions = Vec::new();
                let output = ui.state.egui_ctx().run_ui(input, |ui| panel::draw(ui.ctx(), &state, &mut actions));
                ui.state.handle_platform_output(&self.window, output.platform_output);
                let primitives = ui.state.egui_ctx().tessellate(output.shapes, output.pixels_per_point);
                ui.overlay.set_textures(ctx, &output.textures_delta)?;
                let frame = vk::OverlayFrame { primitives: &primitives, pixels_per_point: output.pixels_per_point };
                let shown = self.presenter.present(ctx, source, copy, Some((&mut ui.overlay, &frame)))?;
                ui.overlay.free_textures(ctx, &output.textures_delta)?;
                self.pending_actions.extend(actions);
                shown
            }
            None => self.presenter.present(ctx, source, copy, None)?,
        };
        self.ui_repaint = false;
        if shown == Presented::Shown && fresh {
            self.unshown = false;
            self.presented += 1;
            self.script_frames = self.script_frames.saturating_sub(1);
        }
        Ok(())
    }

    /// At exit: the `--screenshot`.
    fn finish(&mut self) -> Result<()> {
        log::info!(
            "{} frames presented; the longest turn of the event loop took {:.0} ms",
            self.presented,
            self.longest_turn.as_secs_f64() * 1e3
        );
        if let Some(path) = self.screenshot_at_exit.take() {
            self.refine_now()?;
            self.renderer.write_image(&path)?;
            eprintln!("wrote {}", path.display());
        }
        Ok(())
    }
}

impl Drop for Viewer {
    fn drop(&mut self) {
        // The window image goes first, and a present may still be reading it.
        let _ = self.renderer.ctx.wait_idle();
    }
}

/// Milliseconds per pass, in the order of the frame, passes that repeat (shading submissions) summed.
fn pass_list(scopes: &[TimedScope]) -> Vec<(String, f64)> {
    let mut passes: Vec<(String, f64)> = Vec::new();
    for s in scopes {
        let ms = (s.end_ns - s.begin_ns) / 1e6;
        match passes.iter_mut().find(|(name, _)| *name == s.name) {
            Some((_, total)) => *total += ms,
            None => passes.push((s.name.clone(), ms)),
        }
    }
    passes
}

/// `name ms` per pass (see [`pass_list`]).
fn pass_times(scopes: &[TimedScope]) -> String {
    pass_list(scopes).iter().map(|(name, ms)| format!("{name} {ms:.1} ms")).collect::<Vec<_>>().join(", ")
}

/// `stem-0000.ext`, the first number not taken in the working folder.
fn next_free_path(stem: &str, ext: &str) -> PathBuf {
    (0..10000)
        .map(|i| PathBuf::from(format!("{stem}-{i:04}.{ext}")))
        .find(|p| !p.exists())
        .unwrap_or_else(|| PathBuf::from(format!("{stem}.{ext}")))
}
