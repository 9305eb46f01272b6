//! Cameras and lights, and a scene of one mesh as the command line describes it (settings turn
//! it into a `World` and a `FrameDesc`).

use glam::{Mat4, Vec3};

use crate::bad_input;
use crate::error::Result;
use crate::mesh::Mesh;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub eye: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    /// Vertical field of view in degrees.
    pub fov_y_deg: f32,
}

impl Camera {
    /// A camera looking at a bounding sphere from `direction` (eye side), so that the whole sphere
    /// fits the vertical field of view.
    pub fn framing(centre: Vec3, radius: f32, fov_y_deg: f32, direction: Vec3) -> Camera {
        // Any size a mesh may have (Mesh::validate): no clamp that would lose a tiny object.
        let radius = radius.max(1e-30);
        let half = (fov_y_deg.to_radians() * 0.5).max(1e-3);
        let distance = radius / half.sin() * 1.02;
        Camera { eye: centre + direction.normalize() * distance, target: centre, up: Vec3::Y, fov_y_deg }
    }

    pub fn validate(&self) -> Result<()> {
        let forward = self.target - self.eye;
        if !(self.eye.is_finite() && self.target.is_finite() && self.up.is_finite()) {
            return Err(bad_input!("camera: --eye, --target and --up must be finite"));
        }
        if forward.length() <= 1e-6 * self.eye.abs().max_element().max(self.target.abs().max_element()) {
            return Err(bad_input!("camera: --eye and --target are the same point"));
        }
        if forward.cross(self.up).length() < 1e-6 * forward.length() * self.up.length().max(1e-30) {
            return Err(bad_input!("camera: --up is zero or parallel to the view direction"));
        }
        // Below a thousandth of a degree 1/tan(fov/2) leaves f32 (1e-37 gave an infinite matrix).
        if !(self.fov_y_deg >= 1e-3 && self.fov_y_deg < 180.0) {
            return Err(bad_input!("--fov {}: must be at least 0.001 and below 180 degrees", self.fov_y_deg));
        }
        Ok(())
    }

    /// World → Vulkan clip space (y down, depth 0..1), with near/far planes around `bounds`.
    pub fn view_projection(&self, aspect: f32, bounds: (Vec3, Vec3)) -> Mat4 {
        let view = Mat4::look_at_rh(self.eye, self.target, self.up);
        let centre = (bounds.0 + bounds.1) * 0.5;
        let radius = ((bounds.1 - bounds.0).length() * 0.5).max(1e-30);
        let distance = (centre - self.eye).length();
        let far = distance + radius * 1.5;
        // In f32, far and near can round to the same value when the eye is far away relative to
        // the mesh (eye 4e9 from a unit sphere): keep them apart so the matrix stays finite.
        let mut near = (distance - radius * 1.5).max(far * 1e-4);
        if near >= far {
            near = far * 0.5;
        }
        let mut projection = Mat4::perspective_rh(self.fov_y_deg.to_radians(), aspect, near, far);
        projection.y_axis.y = -projection.y_axis.y;
        projection * view
    }
}

/// A light. Directions point from the surface toward the light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// `irradiance`: W/m² per RGB channel on a surface facing the light.
    Directional { toward: Vec3, irradiance: Vec3 },
    /// `intensity`: W/sr per RGB channel; irradiance falls off with the squared distance.
    Point { position: Vec3, intensity: Vec3 },
    /// A point light shining into a cone: pbrt-v4's `spot` (its `SpotLight::I`, src/pbrt/lights.cpp).
    /// `axis` (unit) points from the light along the cone's centre; `cone_deg` is the cone's
    /// half-angle (pbrt's `coneangle`), beyond which nothing is lit; `delta_deg` (pbrt's
    /// `conedeltaangle`) is the width of the rim over which the intensity falls to 0: at an angle θ
    /// off the axis the intensity is `intensity` × smoothstep(cos θ; cos cone, cos(cone − delta)).
    Spot { position: Vec3, axis: Vec3, intensity: Vec3, cone_deg: f32, delta_deg: f32 },
}

/// Spot lights with a cone's half-angle above this many degrees get a point light's six cube faces
/// for their shadows instead of one perspective map. A perspective map of half-angle θ spends its
/// texels unevenly: a texel at its centre subtends 2 tan θ / N radians, 1/cos²θ times one at its
/// edge; at 60° that is tan 60° = 1.73 times the coarsest texel of a 45° cube face, and it grows
/// without bound toward 90° (where one map cannot hold the cone at all). Up to 60° one layer is at
/// worst 1.73 times coarser than the cube's and costs a sixth of the memory and draws; beyond it
/// the cube is both finer and possible. A 180° spot is then exactly a point light.
pub const SPOT_CUBE_ABOVE_DEG: f32 = 60.0;

impl Light {
    pub fn validate(&self) -> Result<()> {
        match self {
            Light::Directional { toward, irradiance } => {
                if !toward.is_finite() || toward.length() < 1e-12 {
                    return Err(bad_input!("light direction {toward}: must be finite and non-zero"));
                }
                check_power(*irradiance)
            }
            Light::Point { position, intensity } => {
                if !position.is_finite() {
                    return Err(bad_input!("light position {position}: must be finite"));
                }
                check_power(*intensity)
            }
            Light::Spot { position, axis, intensity, cone_deg, delta_deg } => {
                if !position.is_finite() {
                    return Err(bad_input!("light position {position}: must be finite"));
                }
                if !axis.is_finite() || (axis.length() - 1.0).abs() > 1e-4 {
                    return Err(bad_input!("spot light axis {axis}: must be a finite unit vector"));
                }
                check_cone(*cone_deg, *delta_deg).map_err(|e| bad_input!("spot light: {e}"))?;
                check_power(*intensity)
            }
        }
    }

    /// A spot light at `position` aimed at `target`, its cone `cone_deg` degrees from the axis to
    /// the edge with a falloff `delta_deg` wide inside the edge; the error says which is wrong.
    pub fn spot(
        position: Vec3,
        target: Vec3,
        cone_deg: f32,
        delta_deg: f32,
        intensity: Vec3,
    ) -> std::result::Result<Light, String> {
        if !(position.is_finite() && target.is_finite()) {
            return Err(format!("position {position} and target {target} must be finite"));
        }
        let axis = crate::mesh::safe_normalize(target - position)
            .filter(|_| {
                (target - position).length() > 1e-6 * position.abs().max_element().max(target.abs().max_element())
            })
            .ok_or_else(|| format!("position {position} and target {target} are the same point"))?;
        check_cone(cone_deg, delta_deg)?;
        if !intensity.is_finite() || intensity.min_element() < 0.0 {
            return Err(format!("intensity {intensity}: must be finite and non-negative"));
        }
        Ok(Light::Spot { position, axis, intensity, cone_deg, delta_deg })
    }

    /// The same light in units `factor` times smaller (a world re-expressed in other units): a
    /// position scaled by `factor`, and a point or spot light's intensity by factor², so that
    /// its irradiance E = I/d² at every point of the scaled world stays what it was.
    pub fn in_units_scaled_by(&mut self, factor: f32) {
        match self {
            Light::Directional { .. } => {}
            Light::Point { position, intensity } | Light::Spot { position, intensity, .. } => {
                *position *= factor;
                *intensity *= factor * factor;
            }
        }
    }

    /// The light's position (point and spot lights).
    pub fn position(&self) -> Option<Vec3> {
        match *self {
            Light::Directional { .. } => None,
            Light::Point { position, .. } | Light::Spot { position, .. } => Some(position),
        }
    }

    pub fn position_mut(&mut self) -> Option<&mut Vec3> {
        match self {
            Light::Directional { .. } => None,
            Light::Point { position, .. } | Light::Spot { position, .. } => Some(position),
        }
    }

    /// Shadow-map layers: one for a directional light and a spot of at most
    /// [`SPOT_CUBE_ABOVE_DEG`], six cube faces for a point light and a wider spot.
    pub fn shadow_layers(&self) -> u32 {
        match *self {
            Light::Directional { .. } => 1,
            Light::Point { .. } => 6,
            Light::Spot { cone_deg, .. } => {
                if cone_deg > SPOT_CUBE_ABOVE_DEG {
                    6
                } else {
                    1
                }
            }
        }
    }

    /// A spot light's (cos cone, cos(cone − delta)): the bounds of pbrt-v4's smoothstep.
    pub fn spot_cosines(cone_deg: f32, delta_deg: f32) -> (f32, f32) {
        (cone_deg.to_radians().cos(), (cone_deg - delta_deg).to_radians().cos())
    }
}

/// A spot's cone angle in (0, 180] degrees and its falloff width in [0, cone].
fn check_cone(cone_deg: f32, delta_deg: f32) -> std::result::Result<(), String> {
    if !(cone_deg > 0.0 && cone_deg <= 180.0) {
        return Err(format!("cone angle {cone_deg}°: must be in (0, 180] degrees"));
    }
    if !(delta_deg >= 0.0 && delta_deg <= cone_deg) {
        return Err(format!("falloff width {delta_deg}°: must be in [0, {cone_deg}] (0 to the cone angle)"));
    }
    Ok(())
}

impl Light {
    /// The light turned by `angle` radians about the axis `up` through `centre` (directions turn
    /// about `up`, positions about the axis through `centre`).
    pub fn rotated(&self, up: Vec3, angle: f32, centre: Vec3) -> Light {
        self.turned(glam::Quat::from_axis_angle(up.normalize_or(Vec3::Y), angle), centre)
    }

    /// The light turned by `turn` about `centre`, as if carried rigidly: directions and a spot's
    /// axis turn, positions turn about `centre`.
    pub fn turned(&self, turn: glam::Quat, centre: Vec3) -> Light {
        match *self {
            Light::Directional { toward, irradiance } => Light::Directional { toward: turn * toward, irradiance },
            Light::Point { position, intensity } => {
                Light::Point { position: centre + turn * (position - centre), intensity }
            }
            Light::Spot { position, axis, intensity, cone_deg, delta_deg } => Light::Spot {
                position: centre + turn * (position - centre),
                axis: (turn * axis).normalize(),
                intensity,
                cone_deg,
                delta_deg,
            },
        }
    }
}

fn check_power(v: Vec3) -> Result<()> {
    if !v.is_finite() || v.min_element() < 0.0 {
        return Err(bad_input!("light intensity {v}: must be finite and non-negative"));
    }
    Ok(())
}

/// The centre of the bounding box and the radius of the sphere around it that holds every vertex.
pub fn bounding_sphere(positions: &[Vec3]) -> (Vec3, f32) {
    let (lo, hi) =
        positions.iter().fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let centre = (lo + hi) * 0.5;
    let radius = positions.iter().map(|p| (*p - centre).length()).fold(0.0f32, f32::max);
    (centre, radius)
}

#[derive(Clone)]
pub struct Scene {
    pub mesh: Mesh,
    pub camera: Camera,
    pub lights: Vec<Light>,
    /// Millimetres per scene unit (materials are given per mm).
    pub mm_per_unit: f32,
}
