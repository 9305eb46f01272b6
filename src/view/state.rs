//! What the viewer shows: the world and the frame description, and the one route by which an
//! action edits them ([`ViewState::apply`]). Keys, the mouse, the panel and scripts all come here;
//! what an action does to the window (frames, screenshots, resizes, quitting) is the window's.

use glam::Vec3;

use crate::error::Result;
use crate::frame_desc::FrameDesc;
use crate::materials::Material;
use crate::output::Exposure;
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
        let centre = world.objects.first().map(|o| crate::scene::bounding_sphere(&o.mesh.positions).0);
        let exposure_stops = match desc.exposure {
            Exposure::Stops(s) => s,
            Exposure::Auto => 0.0,
        };
        ViewState { world, desc, centre: centre.unwrap_or(Vec3::ZERO), exposure_stops, playing: true }
    }

    /// The material of the (first) object.
    pub fn material(&self) -> &Material {
        &self.world.objects[0].material
    }

    /// Applies one action: the one path for scripts, keys, the mouse and the panel. An edit that
    /// the checks refuse (g ≥ 1 typed on the panel, σ beyond f32) leaves everything as it was.
    pub fn apply(&mut self, action: Action) -> Result<Applied> {
        let (desc_before, material_before) = (self.desc.clone(), self.material().clone());
        let before_stops = self.exposure_stops;
        let d = &mut self.desc;
        match action {
            Action::Orbit { right_deg, up_deg } => controls::orbit(&mut d.camera, right_deg, up_deg),
            Action::Pan { right, up } => controls::pan(&mut d.camera, right, up),
            Action::Zoom(f) => controls::zoom(&mut d.camera, f),
            Action::TurnLights { right_deg, up_deg } => {
                controls::turn_lights(&mut d.lights, &d.camera, self.centre, right_deg, up_deg)
            }
            Action::SetLight(light) => d.lights[0] = light,
            Action::Material(name) => self.world.objects[0].material = Material::find(&name)?,
            Action::TogglePause => self.playing = !self.playing,
            Action::Set(setting) => {
                let m = &mut self.world.objects[0].material;
                match setting {
                    Setting::Epsilon(e) => d.integration.epsilon = e,
                    Setting::Exposure(stops) => {
                        self.exposure_stops = stops.unwrap_or(0.0);
                        d.exposure = stops.map(Exposure::Stops).unwrap_or(Exposure::Auto);
                    }
                    Setting::Specular(on) => d.specular = on,
                    Setting::Roughness(r) => d.roughness = r,
                    Setting::Model(model) => d.integration.model = model,
                    Setting::BruteForce(on) => d.integration.brute_force = on,
                    Setting::SigmaA(v) => m.sigma_a = v,
                    Setting::SigmaS(v) => m.sigma_s = v,
                    Setting::G(v) => m.g = v,
                    Setting::Eta(v) => m.eta = v,
                    Setting::Samples(n) => self.world.objects[0].samples = Some(n),
                    Setting::Show(show) => d.show = show,
                }
            }
            window => return Ok(Applied::Window(window)),
        }
        let checked = crate::world::check_material(self.material()).and_then(|_| self.desc.validate());
        if let Err(e) = checked {
            (self.desc, self.world.objects[0].material) = (desc_before, material_before);
            self.exposure_stops = before_stops;
            return Err(e);
        }
        Ok(Applied::Edited)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Mesh;
    use crate::physics::Model;
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
        assert_eq!(s.material().name, Material::find("skin1").unwrap().name);
        assert_eq!(s.apply(Action::Quit).unwrap(), Applied::Window(Action::Quit));
    }

    /// `set sigma-s 1e7` once skipped the f32 check that only `render` made; a refused edit
    /// leaves the state as it was.
    #[test]
    fn refused_edits_change_nothing() {
        let mut s = state();
        let material = s.material().clone();
        let e = s.apply(Action::Set(Setting::SigmaS([1e7; 3]))).unwrap_err();
        assert!(e.to_string().contains("f32"), "{e}");
        assert_eq!(s.material(), &material);
        let e = s.apply(Action::Set(Setting::Epsilon(f32::NAN))).unwrap_err();
        assert!(e.to_string().contains("--epsilon"), "{e}");
        assert_eq!(s.desc.integration.epsilon, crate::frame_desc::DEFAULT_EPSILON);
        s.apply(Action::Set(Setting::G([1.5; 3]))).unwrap_err();
        assert_eq!(s.material(), &material);
    }
}
