//! What the viewer shows: the world and the frame description, and the one route by which an
//! action edits them ([`ViewState::apply`]). Keys, the mouse, the panel and scripts all come here;
//! what an action does to the window (frames, screenshots, resizes, quitting) is the window's.

use glam::Vec3;

use crate::error::Result;
use crate::frame_desc::FrameDesc;
use crate::materials::Material;
use crate::output::Exposure;
use crate::physics::Model;
use crate::world::World;

use super::controls::{self, Action, Setting};

/// The viewer's world and frame description.
pub struct ViewState {
    pub world: World,
    /// Its size is the window's; a preview renders a copy at a fraction of it.
    pub desc: FrameDesc,
    /// The object's centre: orbits turn about it, point lights too.
    pub centre: Vec3,
    /// The exposure in stops the keys step from (auto counts as 0).
    pub exposure_stops: f32,
    /// Whether a mesh sequence or deformation plays.
    pub playing: bool,
    /// How many of `desc.lights`, at their end, are the environment's samples (the lights before
    /// them are the ones the user gave, which `light` lines and the panel edit).
    pub env_lights: usize,
    /// The environment's own frame (a pbrt scene's light transform; identity from flags) and the
    /// rotation about the up axis on top of it (`--env-rotate`, `env rotate`).
    pub env_frame: glam::Mat3,
    pub env_rotate_deg: f32,
    /// Whether light that enters again was asked for (`--reentry`): drawn while the model is the
    /// Monte Carlo table with the tree, off otherwise (so that the model and brute force can
    /// still be switched).
    pub reentry: bool,
}

/// What [`ViewState::apply`] did with an action.
#[derive(Debug, PartialEq)]
pub enum Applied {
    /// The world or the frame description changed: the next frame shows it.
    Edited,
    /// An action on the window, not on what is drawn (frames, screenshots, resizes, drags to be
    /// turned into motion, traces, quitting): the window carries it out.
    Window(Action),
}

impl ViewState {
    pub fn new(world: World, desc: FrameDesc) -> ViewState {
        // Lights turn about the first object's centre (the first opaque one's where nothing is
        // translucent).
        let first = world.objects.first().map(|o| &o.mesh).or(world.opaque.first().map(|o| &o.mesh));
        let centre = first.map(|mesh| crate::scene::bounding_sphere(&mesh.positions).0);
        let exposure_stops = match desc.exposure {
            Exposure::Stops(s) => s,
            Exposure::Auto => 0.0,
        };
        // The builders append the environment's samples after the other lights.
        let env_lights = desc.environment.as_ref().and_then(|e| e.lights().ok()).map_or(0, |l| l.len());
        let env_frame = desc.environment.as_ref().map_or(glam::Mat3::IDENTITY, |e| e.to_world);
        ViewState {
            reentry: desc.integration.reentry,
            world,
            desc,
            centre: centre.unwrap_or(Vec3::ZERO),
            exposure_stops,
            playing: true,
            env_lights,
            env_frame,
            env_rotate_deg: 0.0,
        }
    }

    /// As [`ViewState::new`] for an environment given by flags: its frame is `--env-rotate`'s
    /// rotation about the up axis, which `env rotate` then replaces.
    pub fn with_env_rotation(mut self, deg: f32) -> ViewState {
        if self.desc.environment.is_some() {
            (self.env_frame, self.env_rotate_deg) = (glam::Mat3::IDENTITY, deg);
        }
        self
    }

    /// The lights the user gave (not the environment's samples).
    pub fn own_lights(&self) -> &[crate::scene::Light] {
        &self.desc.lights[..self.desc.lights.len() - self.env_lights]
    }

    /// The environment after `edit`, and its samples in place of the old ones.
    fn edit_environment(&mut self, edit: controls::EnvEdit) -> Result<()> {
        use crate::environment::{rotation_about_up, Environment, DEFAULT_SAMPLES};
        use controls::EnvEdit;
        let current = self.desc.environment.as_deref().cloned();
        let env = match (edit, current) {
            (EnvEdit::Map(None), _) => None,
            (EnvEdit::Map(Some(spec)), current) => {
                let (scale, samples) = current.map_or((1.0, DEFAULT_SAMPLES), |c| (c.scale, c.samples));
                if self.desc.environment.is_none() {
                    (self.env_frame, self.env_rotate_deg) = (glam::Mat3::IDENTITY, 0.0);
                }
                Some(Environment {
                    name: format!("env {spec}"),
                    radiance: crate::settings::environment_radiance(&spec)?,
                    scale,
                    to_world: rotation_about_up(self.env_rotate_deg) * self.env_frame,
                    samples,
                })
            }
            (_, None) => {
                return Err(crate::bad_input!(
                    "env: there is no environment to change (give one with `env FILE|const:L|sky`)"
                ))
            }
            (EnvEdit::Scale(scale), Some(c)) => Some(Environment { scale, ..c }),
            (EnvEdit::Samples(samples), Some(c)) => Some(Environment { samples, ..c }),
            (EnvEdit::Rotate(deg), Some(c)) => {
                self.env_rotate_deg = deg;
                Some(Environment { to_world: rotation_about_up(deg) * self.env_frame, ..c })
            }
        };
        let samples = match &env {
            Some(e) => e.lights()?,
            None => Vec::new(),
        };
        let own = self.own_lights().len();
        self.desc.lights.truncate(own);
        self.env_lights = samples.len();
        self.desc.lights.extend(samples);
        self.desc.environment = env.map(std::sync::Arc::new);
        Ok(())
    }

    /// The material of the (first) translucent object; none in a world of opaque objects only.
    pub fn material(&self) -> Option<&Material> {
        self.world.objects.first().map(|o| &o.material)
    }

    /// The first translucent object, for an edit of its material or its samples (refused where
    /// nothing is translucent).
    fn first_object(&mut self) -> Result<&mut crate::world::Object> {
        let none = || crate::bad_input!("the scene has no translucent object: no material or samples to edit");
        self.world.objects.first_mut().ok_or_else(none)
    }

    /// Applies one action: the one path for scripts, keys, the mouse and the panel. An edit that
    /// the checks refuse (g ≥ 1 typed on the panel, σ beyond f32) leaves everything as it was.
    pub fn apply(&mut self, action: Action) -> Result<Applied> {
        let (desc_before, material_before) = (self.desc.clone(), self.material().cloned());
        let before = (self.exposure_stops, self.env_lights, self.env_frame, self.env_rotate_deg);
        let own = self.own_lights().len();
        let light_index = |k: usize| {
            if k < own {
                Ok(k)
            } else {
                Err(crate::bad_input!("light {}: there are {own} light(s) besides the environment's samples", k + 1))
            }
        };
        if let Action::Environment(edit) = action {
            if let Err(e) = self.edit_environment(edit) {
                (self.desc, self.env_lights, self.env_frame, self.env_rotate_deg) =
                    (desc_before, before.1, before.2, before.3);
                return Err(e);
            }
            return self.checked(desc_before, material_before, before);
        }
        let d = &mut self.desc;
        match action {
            Action::Orbit { right_deg, up_deg } => controls::orbit(&mut d.camera, right_deg, up_deg),
            Action::Pan { right, up } => controls::pan(&mut d.camera, right, up),
            Action::Zoom(f) => controls::zoom(&mut d.camera, f),
            Action::TurnLights { right_deg, up_deg } => {
                controls::turn_lights(&mut d.lights, &d.camera, self.centre, right_deg, up_deg)
            }
            // The first of the user's lights; with none (an environment alone), a first one.
            Action::SetLight(light) if own == 0 => d.lights.insert(0, light),
            Action::SetLight(light) => d.lights[0] = light,
            Action::SetLightAt(k, light) => d.lights[light_index(k)?] = light,
            Action::AddLight(light) => d.lights.insert(own, light),
            Action::RemoveLight(k) => {
                d.lights.remove(light_index(k)?);
            }
            Action::Material(name) => {
                let preset = Material::find(&name)?;
                let object = self.first_object()?;
                // A textured object keeps its colour, as `--material` makes it.
                object.material = match &object.texture {
                    Some(texture) => crate::world::textured_material(&preset, texture)?,
                    None => preset,
                };
            }
            Action::TogglePause => self.playing = !self.playing,
            Action::Set(setting) => match setting {
                Setting::Epsilon(e) => d.integration.epsilon = e,
                Setting::Exposure(stops) => {
                    self.exposure_stops = stops.unwrap_or(0.0);
                    d.exposure = stops.map(Exposure::Stops).unwrap_or(Exposure::Auto);
                }
                Setting::Specular(on) => d.specular = on,
                Setting::Roughness(r) => d.roughness = r,
                Setting::Model(model) => {
                    d.integration.model = model;
                    d.integration.reentry = self.reentry && model == Model::Mc && !d.integration.brute_force;
                }
                Setting::BruteForce(on) => {
                    d.integration.brute_force = on;
                    d.integration.reentry = self.reentry && d.integration.model == Model::Mc && !on;
                }
                Setting::Show(show) => d.show = show,
                // The first translucent object's material and samples.
                of_object => {
                    let o = self.first_object()?;
                    let m = &mut o.material;
                    match of_object {
                        Setting::SigmaA(v) => m.sigma_a = v,
                        Setting::SigmaS(v) => m.sigma_s = v,
                        Setting::G(v) => m.g = v,
                        Setting::Eta(v) => m.eta = v,
                        Setting::Samples(n) => o.samples = Some(n),
                        _ => unreachable!("the frame's settings are matched above"),
                    }
                }
            },
            window => return Ok(Applied::Window(window)),
        }
        self.checked(desc_before, material_before, before)
    }

    /// Keeps an edit that passes the checks, or puts everything back as it was.
    fn checked(
        &mut self,
        desc_before: FrameDesc,
        material_before: Option<Material>,
        before: (f32, usize, glam::Mat3, f32),
    ) -> Result<Applied> {
        let material = self.material().map_or(Ok(()), crate::world::check_material);
        let checked = material.and_then(|_| self.desc.validate());
        if let Err(e) = checked {
            self.desc = desc_before;
            if let (Some(o), Some(m)) = (self.world.objects.first_mut(), material_before) {
                o.material = m;
            }
            (self.exposure_stops, self.env_lights, self.env_frame, self.env_rotate_deg) = before;
            return Err(e);
        }
        Ok(Applied::Edited)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Mesh;
    use crate::scene::{Camera, Light};

    fn state() -> ViewState {
        let world = World::single(Mesh::sphere(1.0, 8), Material::find("marble").unwrap(), 10.0);
        let camera = Camera { eye: Vec3::new(0.0, 0.0, 5.0), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 40.0 };
        ViewState::new(
            world,
            FrameDesc::new(camera, vec![Light::Directional { toward: Vec3::Y, irradiance: Vec3::ONE }]),
        )
    }

    #[test]
    fn edits_reach_the_description_or_the_world() {
        let mut s = state();
        assert_eq!(s.apply(Action::Set(Setting::Model(Model::Dipole))).unwrap(), Applied::Edited);
        assert_eq!(s.apply(Action::Set(Setting::BruteForce(true))).unwrap(), Applied::Edited);
        assert_eq!(s.apply(Action::Set(Setting::Samples(5000))).unwrap(), Applied::Edited);
        s.apply(Action::Material("skin1".into())).unwrap();
        assert_eq!(s.desc.integration.model, Model::Dipole);
        assert!(s.desc.integration.brute_force);
        assert_eq!(s.world.objects[0].samples, Some(5000));
        assert_eq!(s.material().unwrap().name, Material::find("skin1").unwrap().name);
        assert_eq!(s.apply(Action::Quit).unwrap(), Applied::Window(Action::Quit));
    }

    /// Started with `--reentry`, the model and brute force still switch: light that enters
    /// again is drawn while the Monte Carlo table walks the tree, and again when it comes back.
    #[test]
    fn light_that_enters_again_follows_the_model() {
        let mut s = state();
        s.desc.integration.model = Model::Mc;
        s.desc.integration.reentry = true;
        s.reentry = true;
        assert_eq!(s.apply(Action::Set(Setting::Model(Model::Directional))).unwrap(), Applied::Edited);
        assert!(!s.desc.integration.reentry);
        s.apply(Action::Set(Setting::Model(Model::Mc))).unwrap();
        assert!(s.desc.integration.reentry);
        s.apply(Action::Set(Setting::BruteForce(true))).unwrap();
        assert!(!s.desc.integration.reentry && s.desc.integration.brute_force);
        s.apply(Action::Set(Setting::BruteForce(false))).unwrap();
        assert!(s.desc.integration.reentry);
    }

    /// Lights are added, moved and removed before the environment's samples; the environment's
    /// map, scale, rotation and sample count replace its samples, and a refused edit changes
    /// nothing.
    #[test]
    fn lights_and_the_environment_are_edited() {
        use crate::environment::rotation_about_up;
        use controls::EnvEdit;
        let mut s = state();
        let point = Light::Point { position: Vec3::new(1.0, 2.0, 3.0), intensity: Vec3::ONE };
        s.apply(Action::Environment(EnvEdit::Map(Some("sky:20:90".into())))).unwrap();
        s.apply(Action::Environment(EnvEdit::Samples(16))).unwrap();
        assert_eq!((s.own_lights().len(), s.env_lights, s.desc.lights.len()), (1, 16, 17));
        s.apply(Action::AddLight(point)).unwrap();
        assert_eq!(s.own_lights()[1], point);
        let moved = Light::Point { position: Vec3::new(-1.0, 0.0, 0.0), intensity: Vec3::ONE };
        s.apply(Action::SetLightAt(1, moved)).unwrap();
        assert_eq!(s.own_lights()[1], moved);
        assert!(s.apply(Action::SetLightAt(2, moved)).is_err(), "only two lights of the user's");
        // The samples as `--env sky:20:90 --env-scale 0.5 --env-rotate 30 --env-samples 16` gives them.
        s.apply(Action::Environment(EnvEdit::Scale(0.5))).unwrap();
        s.apply(Action::Environment(EnvEdit::Rotate(30.0))).unwrap();
        let env = crate::environment::Environment {
            name: "sky".into(),
            radiance: crate::environment::sky(20.0, 90.0),
            scale: 0.5,
            to_world: rotation_about_up(30.0),
            samples: 16,
        };
        assert_eq!(s.desc.lights[2..], env.lights().unwrap()[..]);
        assert_eq!(s.desc.environment.as_ref().unwrap().to_world, rotation_about_up(30.0));
        s.apply(Action::RemoveLight(0)).unwrap();
        assert_eq!(s.own_lights(), &[moved]);
        assert!(s.apply(Action::Environment(EnvEdit::Map(Some("/no/such/map.exr".into())))).is_err());
        assert_eq!(s.env_lights, 16, "a refused map leaves the environment as it was");
        s.apply(Action::Environment(EnvEdit::Map(None))).unwrap();
        assert_eq!((s.desc.lights.len(), s.env_lights, s.desc.environment.is_none()), (1, 0, true));
        assert!(s.apply(Action::RemoveLight(0)).is_err(), "the last light stays");
        assert!(s.apply(Action::Environment(EnvEdit::Scale(2.0))).is_err(), "no environment to scale");
        assert_eq!(s.own_lights(), &[moved]);
    }

    /// `set sigma-s 1e7` once skipped the f32 check that only `render` made; a refused edit
    /// leaves the state as it was.
    #[test]
    fn refused_edits_change_nothing() {
        let mut s = state();
        let material = s.material().unwrap().clone();
        let e = s.apply(Action::Set(Setting::SigmaS([1e7; 3]))).unwrap_err();
        assert!(e.to_string().contains("f32"), "{e}");
        assert_eq!(s.material(), Some(&material));
        let e = s.apply(Action::Set(Setting::Epsilon(f32::NAN))).unwrap_err();
        assert!(e.to_string().contains("--epsilon"), "{e}");
        assert_eq!(s.desc.integration.epsilon, crate::frame_desc::DEFAULT_EPSILON);
        s.apply(Action::Set(Setting::G([1.5; 3]))).unwrap_err();
        assert_eq!(s.material(), Some(&material));
    }

    /// Nothing translucent (a scene of diffuse shapes, issue #28): the frame's settings and the
    /// lights are edited; the material and the samples are refused, changing nothing.
    #[test]
    fn a_world_of_opaque_objects_edits_all_but_the_material() {
        let mut s = state();
        let opaque =
            crate::world::Opaque::new(Mesh::sphere(1.0, 8), crate::world::Reflectance::Constant(Vec3::splat(0.5)));
        (s.world.objects, s.world.opaque) = (Vec::new(), vec![opaque]);
        assert_eq!(s.material(), None);
        assert_eq!(s.apply(Action::Set(Setting::Roughness(0.5))).unwrap(), Applied::Edited);
        assert_eq!(s.apply(Action::Set(Setting::Show(crate::frame_desc::Show::Samples))).unwrap(), Applied::Edited);
        s.apply(Action::AddLight(Light::Directional { toward: Vec3::X, irradiance: Vec3::ONE })).unwrap();
        assert_eq!(s.own_lights().len(), 2);
        let world = s.world.clone();
        for refused in
            [Action::Material("skin1".into()), Action::Set(Setting::G([0.5; 3])), Action::Set(Setting::Samples(5000))]
        {
            let e = s.apply(refused).unwrap_err();
            assert!(e.to_string().contains("no translucent object"), "{e}");
        }
        assert_eq!(s.world, world);
    }
}
