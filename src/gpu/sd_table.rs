//! A radial profile Sd(r) as the shade pass reads it: a table of f16 pairs (bssrdf.glsl's
//! `dipole_sd_table`), made from the classical dipole's [`crate::physics::dipole::sd`] or photon
//! beam diffusion's [`crate::physics::beam_diffusion::sd`] and tested against them.

use crate::physics::beam_diffusion::{self, BeamMedium};
use crate::physics::curvature_profile::{self, CurvatureChannel};
use crate::physics::mc_profile::{self, McProfile};
use crate::physics::slab_profile::{self, SlabChannel};
use crate::physics::{dipole, ChannelConstants};

/// Entries of [`SdTable`] (shared with bssrdf.glsl).
pub const TABLE_SIZE: usize = super::DIPOLE_TABLE_SIZE as usize;

/// A radial Sd for three channels, tabulated for the shade pass: entry i holds Sd at
/// u = i/(TABLE_SIZE − 1) of the map u = r/(r + reach), r in mm, and the last entry (r = ∞) is 0.
/// One lookup gives the three channels for a few operations where the classical dipole's closed
/// form costs 6 square roots, 6 exponentials and 6 divisions (and beam diffusion's integrals
/// hundreds); linear interpolation between entries stays within 1e-4 of Sd(0) and 2e-3 of the
/// classical dipole's closed form, and within 2e-3 of beam diffusion's from a hundredth of a mean
/// free path on (tested).
#[derive(Clone, Debug, PartialEq)]
pub struct SdTable {
    /// The map's scale, in mm: 1/σtr of the channel that reaches farthest.
    pub reach: f64,
    /// The largest entry per channel / 2^15 (1/mm²; Sd(0) for these decreasing profiles): the
    /// entries are Sd/scale, in [0, 2^15], so that Sd down to 2e-9 of the peak keeps f16's full
    /// precision (normal numbers start at 2^-14).
    pub scale: [f32; 3],
    /// Sd / scale per channel at each entry, rounded to f16 (as the GPU reads it).
    pub values: Vec<[u16; 3]>,
    /// The Monte Carlo table's azimuthal harmonic b per channel at each entry
    /// ([`McProfile::azimuth`]), packed as three 10-bit signed fixed-point values
    /// ([`pack_azimuth`]) in the texel's spare word; 0 for the other profiles.
    pub azimuth: Vec<u32>,
}

/// Three values in [−2, 2] (b sin θt is a first harmonic: at most 2) as 10-bit signed fixed
/// point (steps of 2/511), bits 0–9, 10–19, 20–29 (bssrdf.glsl's `sd_table_azimuth`).
pub fn pack_azimuth(b: [f64; 3]) -> u32 {
    let q = |x: f64| ((x.clamp(-2.0, 2.0) * 255.5).round() as i32 & 0x3ff) as u32;
    q(b[0]) | q(b[1]) << 10 | q(b[2]) << 20
}

/// The values [`pack_azimuth`] packed.
pub fn unpack_azimuth(w: u32) -> [f64; 3] {
    [0, 10, 20].map(|shift| {
        let v = ((w >> shift) & 0x3ff) as i32;
        (if v >= 512 { v - 1024 } else { v }) as f64 / 255.5
    })
}

impl SdTable {
    /// The table of `profile(channel, r)` (1/mm², r in mm, finite at r = 0) on the map of `reach`.
    pub fn from_profile(reach: f64, profile: impl Fn(usize, f64) -> f64 + Sync) -> SdTable {
        let last = TABLE_SIZE - 1;
        let entry = |i: usize| {
            let u = i as f64 / last as f64;
            let r = reach * u / (1.0 - u);
            [0, 1, 2].map(|c| if i == last { 0.0 } else { profile(c, r) })
        };
        // Beam diffusion's profile costs hundreds of exponentials an entry: both cores.
        let half = TABLE_SIZE / 2;
        let (low, high) = std::thread::scope(|s| {
            let high = s.spawn(|| (half..TABLE_SIZE).map(entry).collect::<Vec<_>>());
            let low: Vec<[f64; 3]> = (0..half).map(entry).collect();
            (low, high.join().expect("table thread"))
        });
        let raw: Vec<[f64; 3]> = low.into_iter().chain(high).collect();
        let scale = [0, 1, 2].map(|c| (raw.iter().map(|v| v[c]).fold(0.0, f64::max) / 32768.0) as f32);
        let values = raw
            .iter()
            .map(|v| [0, 1, 2].map(|c| half_bits(if scale[c] > 0.0 { (v[c] / scale[c] as f64) as f32 } else { 0.0 })))
            .collect();
        SdTable { reach, scale, values, azimuth: vec![0; TABLE_SIZE] }
    }

    /// The classical dipole's table.
    pub fn dipole(channels: &[ChannelConstants; 3]) -> SdTable {
        let sigma_tr =
            channels.iter().filter(|c| c.transports).map(|c| c.dipole_sigma_tr).fold(f64::INFINITY, f64::min);
        SdTable::from_profile(reach_of(sigma_tr), |c, r| dipole::sd(&channels[c], r))
    }

    /// Photon beam diffusion's table. The same reach as the dipole's (its own σtr): single
    /// scattering, the sharp part, falls off over a mean free path 1/σt, which is 1/σtr ×
    /// √(3(1 − α')) or less: thousands of entries per 1/σtr near r = 0 resolve it (tested).
    ///
    /// Sd is singular at r = 0 (single scattering as 1/r): entry 0 holds instead the value that
    /// gives the first interval, interpolated linearly, the profile's own share of ∫Sd dA.
    pub fn beam_diffusion(media: &[BeamMedium; 3]) -> SdTable {
        let sigma_tr = media.iter().filter(|b| b.transports()).map(|b| b.sigma_tr).fold(f64::INFINITY, f64::min);
        let reach = reach_of(sigma_tr);
        SdTable::from_profile(reach, |c, r| beam_diffusion_entry(&media[c], reach, r))
    }

    /// Beam diffusion's table of one medium, in channel 0 (the others 0): `bssrdf --gpu`'s, whose
    /// rows each have a medium of their own.
    pub fn beam_diffusion_one(medium: &BeamMedium) -> SdTable {
        let sigma_tr = if medium.transports() { medium.sigma_tr } else { f64::INFINITY };
        let reach = reach_of(sigma_tr);
        SdTable::from_profile(reach, |c, r| if c == 0 { beam_diffusion_entry(medium, reach, r) } else { 0.0 })
    }

    /// The table as the shade pass's texels (RGBA32UI): texel 0 holds the three scales and the
    /// reach (f32 bits); texel 1 + i holds, per channel, entries i and i + 1 as two f16 (low,
    /// high), so that one fetch gives both ends of the interpolation.
    pub fn texels(&self) -> Vec<[u32; 4]> {
        let mut texels = vec![[
            self.scale[0].to_bits(),
            self.scale[1].to_bits(),
            self.scale[2].to_bits(),
            (self.reach as f32).to_bits(),
        ]];
        texels.extend(self.values.windows(2).zip(&self.azimuth).map(|(w, &b)| {
            let pair = |c: usize| w[0][c] as u32 | (w[1][c] as u32) << 16;
            [pair(0), pair(1), pair(2), b]
        }));
        texels
    }

    /// Entry `i`'s value in channel 0 (1/mm²).
    pub fn lookup_entry(&self, i: usize) -> f64 {
        self.scale[0] as f64 * half_value(self.values[i][0])
    }

    /// Sd per channel at distance `r` (mm), as the shade pass reads it: `dipole_sd_table` in
    /// shaders/include/bssrdf.glsl.
    pub fn lookup(&self, r: f64) -> [f64; 3] {
        let x = r / (r + self.reach) * (TABLE_SIZE - 1) as f64;
        let i = (x.floor() as usize).min(TABLE_SIZE - 2);
        let f = x - i as f64;
        let (a, b) = (self.values[i], self.values[i + 1]);
        [0, 1, 2].map(|c| self.scale[c] as f64 * (half_value(a[c]) * (1.0 - f) + half_value(b[c]) * f))
    }
}

impl SdTable {
    /// The half-space Monte Carlo's table (`--model mc`): its measured radial profile. The same
    /// reach as the classical dipole's.
    /// Its texels carry the azimuthal harmonic, entry i's (nearest: the entries are 4096).
    pub fn monte_carlo(profiles: &[std::sync::Arc<McProfile>; 3], channels: &[ChannelConstants; 3]) -> SdTable {
        let sigma_tr =
            channels.iter().filter(|c| c.transports).map(|c| c.dipole_sigma_tr).fold(f64::INFINITY, f64::min);
        let mut table = SdTable::from_profile(reach_of(sigma_tr), |c, r| profiles[c].sd(r));
        table.azimuth = (0..TABLE_SIZE)
            .map(|i| {
                let u = i as f64 / (TABLE_SIZE - 1) as f64;
                let r = if i + 1 < TABLE_SIZE { table.reach * u / (1.0 - u) } else { f64::MAX };
                pack_azimuth([0, 1, 2].map(|c| profiles[c].azimuth_factor(r)))
            })
            .collect();
        table
    }

    /// The azimuthal harmonic per channel at distance `r` (mm), as the shade pass reads it
    /// (`sd_table_azimuth`): entry ⌊x⌋'s.
    pub fn azimuth_at(&self, r: f64) -> [f64; 3] {
        let x = r / (r + self.reach) * (TABLE_SIZE - 1) as f64;
        unpack_azimuth(self.azimuth[(x.floor() as usize).min(TABLE_SIZE - 2)])
    }

    /// The Monte Carlo table of one medium, in channel 0 (`bssrdf --gpu`'s, as
    /// [`SdTable::beam_diffusion_one`]).
    pub fn monte_carlo_one(m: &crate::physics::Medium) -> SdTable {
        let c = m.constants(crate::physics::Diffusion::Classical);
        let profile = McProfile::of(m);
        let reach = reach_of(if c.transports { c.dipole_sigma_tr } else { f64::INFINITY });
        SdTable::from_profile(reach, |ch, r| if ch == 0 { profile.sd(r) } else { 0.0 })
    }
}

const _: () = assert!(mc_profile::INCIDENCE_NODES == super::MC_INCIDENCE_NODES as usize);
const _: () = assert!(mc_profile::EXIT_BINS == super::MC_EXIT_BINS as usize);

/// The angular factors of a table model, after its Sd table in the same buffer (bssrdf.glsl's
/// `table_incidence_factor`, `table_exit_factor`): the Monte Carlo table's f(θt) and h(θt, θo)
/// ([`McProfile`]), 1 for the other models (which the shaders then multiply by exactly 1).
#[derive(Clone, Debug, PartialEq)]
pub struct AngularFactors {
    /// cos θt of incidence node 0.
    pub cos_t_min: f32,
    pub incidence: [[f32; 3]; mc_profile::INCIDENCE_NODES],
    /// Per incidence node, per exit bin.
    pub exit: [[[f32; 3]; mc_profile::EXIT_BINS]; mc_profile::INCIDENCE_NODES],
}

impl AngularFactors {
    /// No factors: 1 at every node.
    pub fn none() -> AngularFactors {
        AngularFactors {
            cos_t_min: 0.0,
            incidence: [[1.0; 3]; mc_profile::INCIDENCE_NODES],
            exit: [[[1.0; 3]; mc_profile::EXIT_BINS]; mc_profile::INCIDENCE_NODES],
        }
    }

    /// The Monte Carlo table's (the channels share η, so cos θt of node 0 too).
    pub fn monte_carlo(profiles: &[std::sync::Arc<McProfile>; 3]) -> AngularFactors {
        AngularFactors {
            cos_t_min: profiles[0].cos_t_min as f32,
            incidence: std::array::from_fn(|k| [0, 1, 2].map(|c| profiles[c].incidence[k] as f32)),
            exit: std::array::from_fn(|k| std::array::from_fn(|b| [0, 1, 2].map(|c| profiles[c].exit[k][b] as f32))),
        }
    }

    /// Texel TABLE_SIZE + k of the object's table buffer: the incidence factors at node k (and,
    /// in w, cos θt of node 0), then the exit factors, node by node, bin by bin (f32 bits).
    pub fn texels(&self) -> Vec<[u32; 4]> {
        let incidence = self.incidence.iter().map(|f| [f[0], f[1], f[2], self.cos_t_min].map(f32::to_bits));
        let exit = self.exit.iter().flatten().map(|h| [h[0], h[1], h[2], 0.0].map(f32::to_bits));
        incidence.chain(exit).collect()
    }

    /// Texels after the Sd table.
    pub const TEXELS: usize = mc_profile::INCIDENCE_NODES * (1 + mc_profile::EXIT_BINS);
}

const _: () = assert!(slab_profile::THICKNESS_NODES == super::SLAB_THICKNESS_NODES as usize);
const _: () = assert!(slab_profile::LOOKUP_NODES == super::SLAB_LOOKUP_NODES as usize);
const _: () = assert!(slab_profile::ENTRIES == super::SLAB_ENTRIES as usize);
const _: () = assert!(slab_profile::FIRST_NODE_LOG2 + 8 == super::SLAB_FIRST_NODE_LOG2_PLUS_8 as i32);
const _: () = assert!(slab_profile::OBLIQUE_ROWS == super::SLAB_OBLIQUE_ROWS as usize);

/// The Monte Carlo table's light across an object, after the angular factors in the same buffer
/// (bssrdf.glsl's `slab_transmission`, `slab_exit_factor`; [`SlabChannel`]): a header texel (L in
/// mm, then the channels' scales; L = 0 for the other models, which never read the rest), then
/// per lookup node its ENTRIES texels, texel i holding entries i and i + 1 of T·reach² / scale
/// per channel as two f16 (as [`SdTable`]: one fetch per node), then per measured node its
/// EXIT_BINS exit factors h_T (f32 bits), then per measured node its OBLIQUE_ROWS factors of
/// incidence (f32 bits; `slab_oblique_factor`), then per lookup node its ENTRIES texels of the lit
/// face's ratio to the half-space, entries i and i + 1 as two f16 (`slab_reflected_ratio`).
#[derive(Clone, Debug, PartialEq)]
pub struct SlabTransmission {
    pub unit_mm: f32,
    /// Per channel: the largest value / 2^15, so that f16 stays normal down to 2e-9 of it.
    pub scale: [f32; 3],
    /// Per lookup node, per entry: f16 bits of T·reach² / scale.
    pub values: Vec<[[u16; 3]; slab_profile::ENTRIES]>,
    /// Per measured node, per exit bin.
    pub exit: Vec<[[f32; 3]; slab_profile::EXIT_BINS]>,
    /// Per measured node, per row of incidence.
    pub oblique: Vec<[[f32; 3]; slab_profile::OBLIQUE_ROWS]>,
    /// Per lookup node, per entry: f16 bits of R_slab/R_hs ([`SlabChannel::reflected`]).
    pub reflected: Vec<[[u16; 3]; slab_profile::ENTRIES]>,
}

impl SlabTransmission {
    /// Nothing across (the models without it).
    pub fn none() -> SlabTransmission {
        SlabTransmission {
            unit_mm: 0.0,
            scale: [0.0; 3],
            values: vec![[[0; 3]; slab_profile::ENTRIES]; slab_profile::LOOKUP_NODES],
            exit: vec![[[1.0; 3]; slab_profile::EXIT_BINS]; slab_profile::THICKNESS_NODES],
            oblique: vec![[[1.0; 3]; slab_profile::OBLIQUE_ROWS]; slab_profile::THICKNESS_NODES],
            reflected: vec![[[half_bits(1.0); 3]; slab_profile::ENTRIES]; slab_profile::LOOKUP_NODES],
        }
    }

    pub fn monte_carlo(channels: &[std::sync::Arc<SlabChannel>; 3]) -> SlabTransmission {
        let scale = [0, 1, 2].map(|c| {
            let peak = channels[c].lookup.iter().flatten().fold(0.0f64, |a, &b| a.max(b));
            if peak > 0.0 {
                (peak / 32768.0) as f32
            } else {
                1.0
            }
        });
        SlabTransmission {
            unit_mm: channels[0].unit_mm as f32,
            scale,
            values: (0..slab_profile::LOOKUP_NODES)
                .map(|j| {
                    std::array::from_fn(|i| {
                        [0, 1, 2].map(|c| half_bits((channels[c].lookup[j][i] / scale[c] as f64) as f32))
                    })
                })
                .collect(),
            exit: (0..slab_profile::THICKNESS_NODES)
                .map(|k| std::array::from_fn(|b| [0, 1, 2].map(|c| channels[c].exit[k][b] as f32)))
                .collect(),
            oblique: (0..slab_profile::THICKNESS_NODES)
                .map(|k| std::array::from_fn(|q| [0, 1, 2].map(|c| channels[c].oblique[k][q] as f32)))
                .collect(),
            reflected: (0..slab_profile::LOOKUP_NODES)
                .map(|j| std::array::from_fn(|i| [0, 1, 2].map(|c| half_bits(channels[c].reflected[j][i] as f32))))
                .collect(),
        }
    }

    /// T·reach² of lookup node `j`, entry `i`, channel `c`, as the shader reads it.
    pub fn value(&self, j: usize, i: usize, c: usize) -> f64 {
        self.scale[c] as f64 * half_value(self.values[j][i][c])
    }

    pub fn texels(&self) -> Vec<[u32; 4]> {
        let header = std::iter::once([self.unit_mm, self.scale[0], self.scale[1], self.scale[2]].map(f32::to_bits));
        // Texel i: entries i and i + 1 (past the last: `beyond`), so that one fetch interpolates.
        let paired = |nodes: &[[[u16; 3]; slab_profile::ENTRIES]], beyond: Option<u16>| -> Vec<[u32; 4]> {
            nodes
                .iter()
                .flat_map(|node| {
                    (0..slab_profile::ENTRIES).map(move |i| {
                        let next = |c: usize| match node.get(i + 1) {
                            Some(n) => n[c],
                            None => beyond.unwrap_or(node[i][c]),
                        };
                        let pair = |c: usize| node[i][c] as u32 | (next(c) as u32) << 16;
                        [pair(0), pair(1), pair(2), 0]
                    })
                })
                .collect()
        };
        // T falls to 0 past the last entry; the ratio is held there.
        let pairs = paired(&self.values, Some(0));
        let exit = self.exit.iter().flatten().map(|h| [h[0], h[1], h[2], 0.0].map(f32::to_bits));
        let oblique = self.oblique.iter().flatten().map(|f| [f[0], f[1], f[2], 0.0].map(f32::to_bits));
        let reflected = paired(&self.reflected, None);
        header.chain(pairs).chain(exit).chain(oblique).chain(reflected).collect()
    }

    /// Texels after the angular factors.
    pub const TEXELS: usize = 1
        + slab_profile::LOOKUP_NODES * slab_profile::ENTRIES
        + slab_profile::THICKNESS_NODES * slab_profile::EXIT_BINS
        + slab_profile::THICKNESS_NODES * slab_profile::OBLIQUE_ROWS
        + slab_profile::LOOKUP_NODES * slab_profile::ENTRIES;
}

const _: () = assert!(curvature_profile::CURVATURE_NODES == super::CURVATURE_NODES as usize);
const _: () = assert!(curvature_profile::FIRST_CURVATURE_LOG2 + 8 == super::CURVATURE_FIRST_LOG2_PLUS_8 as i32);
const _: () = assert!(curvature_profile::INCIDENCES == super::CURVATURE_INCIDENCES as usize);
const _: () = assert!(curvature_profile::INCIDENCE_SIN2[0] == 0.0);
const _: () = assert!(curvature_profile::INCIDENCE_SIN2[1] == super::CURVATURE_SIN2_PERCENT_1 as f64 / 100.0);
const _: () = assert!(curvature_profile::INCIDENCE_SIN2[2] == super::CURVATURE_SIN2_PERCENT_2 as f64 / 100.0);

/// Entries per row of [`CurvatureRatios`] (bssrdf.glsl reads the nearest: fine enough that
/// rounding r moves a ratio by under 1%; tests/curvature_profile.rs).
pub const CURVATURE_TABLE_ENTRIES: usize = super::CURVATURE_TABLE_ENTRIES as usize;
/// Entries of [`CurvatureRatios`]'s exit tilt (bssrdf.glsl's `exit_terms`).
pub const EXIT_TILT_ENTRIES: usize = super::EXIT_TILT_ENTRIES as usize;

/// The Monte Carlo table's curvature ratios, after the light across in the same buffer
/// (bssrdf.glsl's `curvature_rows`, `curvature_ratio`; [`CurvatureChannel`], resampled at
/// CURVATURE_TABLE_ENTRIES centres of u = s/(s + 1), s = r·κ the chord relative to the node's
/// radius, so that a texel pairs two nodes at the same place on their balls, as
/// [`CurvatureChannel::ratio`] reads them): a header texel (L in mm; 0 for the other
/// models, which never read the rest), then per angle of incidence (curvature_profile's
/// INCIDENCE_SIN2) 2N rows of entries, each texel holding per channel two neighbouring curvature
/// nodes' ratios as two f16, so that one fetch interpolates in κ: on each side (convex, then
/// concave) row j holds nodes j − 1 and j, node −1 being the flat surface (every ratio 1). Then the exit distribution's ratios (`curvature_exit`;
/// [`CurvatureChannel::exit_ratio`]): per angle of incidence the same 2N rows of MC_EXIT_BINS texels, paired the same way,
/// of the light from within a chord R√2, then 2N more of the light from beyond it. Then the
/// Monte Carlo table's exit tilt [c, g] ([`McProfile::exit_tilt_at`]) at EXIT_TILT_ENTRIES
/// centres of u = r/(r + L), one texel each: f16 pairs (c_r, c_g), (c_b, g_r), (g_g, g_b)
/// (`exit_terms`; it rides here, where L is read per pixel anyway, as the Sd table's texels have
/// no word left). Then the higher azimuthal harmonics [b₂, b₃] ([`McProfile::higher_harmonics`])
/// at the same centres, f16 pairs (b₂_r, b₂_g), (b₂_b, b₃_r), (b₃_g, b₃_b) (`exit_terms`, at the same entry);
/// then the radial profile's change with incidence a ([`McProfile::radial_at`]), f16 pairs
/// (a_r, a_g), (a_b, 0), (0, 0).
#[derive(Clone, Debug, PartialEq)]
pub struct CurvatureRatios {
    pub unit_mm: f32,
    /// Per angle of incidence, per side, per node, per entry, per channel.
    pub convex: [Vec<Vec<[f32; 3]>>; curvature_profile::INCIDENCES],
    pub concave: [Vec<Vec<[f32; 3]>>; curvature_profile::INCIDENCES],
    /// Per angle of incidence, per side, per node, per exit bin, per channel.
    pub convex_exit: [Vec<Vec<[f32; 3]>>; curvature_profile::INCIDENCES],
    pub concave_exit: [Vec<Vec<[f32; 3]>>; curvature_profile::INCIDENCES],
    pub convex_exit_far: [Vec<Vec<[f32; 3]>>; curvature_profile::INCIDENCES],
    pub concave_exit_far: [Vec<Vec<[f32; 3]>>; curvature_profile::INCIDENCES],
    /// Per entry, [c, g] per channel.
    pub exit_tilt: Vec<[[f32; 3]; 2]>,
    /// Per entry, [b₂, b₃] per channel.
    pub harmonics: Vec<[[f32; 3]; 2]>,
    /// Per entry, [a, 0] per channel.
    pub radial: Vec<[[f32; 3]; 2]>,
}

impl CurvatureRatios {
    pub const ROWS: usize = 2 * curvature_profile::CURVATURE_NODES;

    /// No ratios (the models without them): L = 0, every node flat.
    pub fn none() -> CurvatureRatios {
        let flat = vec![vec![[1.0; 3]; CURVATURE_TABLE_ENTRIES]; curvature_profile::CURVATURE_NODES];
        let flat_exit = vec![vec![[1.0; 3]; mc_profile::EXIT_BINS]; curvature_profile::CURVATURE_NODES];
        CurvatureRatios {
            unit_mm: 0.0,
            convex: std::array::from_fn(|_| flat.clone()),
            concave: std::array::from_fn(|_| flat.clone()),
            convex_exit: std::array::from_fn(|_| flat_exit.clone()),
            concave_exit: std::array::from_fn(|_| flat_exit.clone()),
            convex_exit_far: std::array::from_fn(|_| flat_exit.clone()),
            concave_exit_far: std::array::from_fn(|_| flat_exit.clone()),
            exit_tilt: vec![[[0.0; 3]; 2]; EXIT_TILT_ENTRIES],
            harmonics: vec![[[0.0; 3]; 2]; EXIT_TILT_ENTRIES],
            radial: vec![[[0.0; 3]; 2]; EXIT_TILT_ENTRIES],
        }
    }

    /// The ratios of `channels` and the exit tilt of `profiles` (the same medium's).
    pub fn monte_carlo(
        channels: &[std::sync::Arc<CurvatureChannel>; 3],
        profiles: &[std::sync::Arc<McProfile>; 3],
    ) -> CurvatureRatios {
        let unit = channels[0].unit_mm;
        let nodes = |sign: f64, j: usize| -> Vec<Vec<[f32; 3]>> {
            (0..curvature_profile::CURVATURE_NODES)
                .map(|k| {
                    let radius = unit / curvature_profile::node_curvature(k);
                    (0..CURVATURE_TABLE_ENTRIES)
                        .map(|i| {
                            let u = (i as f64 + 0.5) / CURVATURE_TABLE_ENTRIES as f64;
                            let chord = radius * u / (1.0 - u);
                            [0, 1, 2].map(|c| channels[c].node_ratio(sign < 0.0, j, k, chord) as f32)
                        })
                        .collect()
                })
                .collect()
        };
        let exits = |concave: bool, far: bool, j: usize| -> Vec<Vec<[f32; 3]>> {
            (0..curvature_profile::CURVATURE_NODES)
                .map(|k| {
                    (0..mc_profile::EXIT_BINS)
                        .map(|b| {
                            [0, 1, 2].map(|c| {
                                let ch = &channels[c];
                                let rows = match (concave, far) {
                                    (false, false) => &ch.convex_exit,
                                    (true, false) => &ch.concave_exit,
                                    (false, true) => &ch.convex_exit_far,
                                    (true, true) => &ch.concave_exit_far,
                                };
                                rows[j][k][b] as f32
                            })
                        })
                        .collect()
                })
                .collect()
        };
        if unit.is_nan() || unit <= 0.0 {
            return CurvatureRatios::none();
        }
        // Two values per channel (`at(channel, r)`) at the EXIT_TILT_ENTRIES centres of u = r/(r + L).
        let per_exit_entry = |at: &dyn Fn(usize, f64) -> [f64; 2]| -> Vec<[[f32; 3]; 2]> {
            (0..EXIT_TILT_ENTRIES)
                .map(|i| {
                    let u = (i as f64 + 0.5) / EXIT_TILT_ENTRIES as f64;
                    let v = [0, 1, 2].map(|c| at(c, unit * u / (1.0 - u)));
                    [0, 1].map(|j| v.map(|t| t[j] as f32))
                })
                .collect()
        };
        CurvatureRatios {
            unit_mm: unit as f32,
            convex: std::array::from_fn(|j| nodes(1.0, j)),
            concave: std::array::from_fn(|j| nodes(-1.0, j)),
            convex_exit: std::array::from_fn(|j| exits(false, false, j)),
            concave_exit: std::array::from_fn(|j| exits(true, false, j)),
            convex_exit_far: std::array::from_fn(|j| exits(false, true, j)),
            concave_exit_far: std::array::from_fn(|j| exits(true, true, j)),
            exit_tilt: per_exit_entry(&|c, r| profiles[c].exit_tilt_at(r)),
            harmonics: per_exit_entry(&|c, r| profiles[c].higher_harmonics(r)),
            radial: per_exit_entry(&|c, r| [profiles[c].radial_at(r), 0.0]),
        }
    }

    /// The exit tilt [c, g] per channel at distance `r_mm`, as the shade pass reads it
    /// (`exit_terms`'s c, g): the nearest entry, in f16; 0 without ratios.
    pub fn exit_tilt_at(&self, r_mm: f64) -> [[f64; 3]; 2] {
        let unit = self.unit_mm as f64;
        if unit.is_nan() || unit <= 0.0 {
            return [[0.0; 3]; 2];
        }
        self.exit_tilt[Self::exit_entry(r_mm, unit)].map(|v| v.map(|x| half_value(half_bits(x))))
    }

    /// The higher azimuthal harmonics [b₂, b₃] per channel at distance `r_mm`, as the shade pass
    /// reads them (`exit_terms`'s b₂, b₃, at the tilt's entry): the nearest entry, in f16; 0 without ratios.
    pub fn harmonics_at(&self, r_mm: f64) -> [[f64; 3]; 2] {
        let unit = self.unit_mm as f64;
        if unit.is_nan() || unit <= 0.0 {
            return [[0.0; 3]; 2];
        }
        self.harmonics[Self::exit_entry(r_mm, unit)].map(|v| v.map(|x| half_value(half_bits(x))))
    }

    /// The radial change a per channel at distance `r_mm`, as the shade pass reads it
    /// (`exit_terms`'s a, at the tilt's entry): the nearest entry, in f16; 0 without ratios.
    pub fn radial_at(&self, r_mm: f64) -> [f64; 3] {
        let unit = self.unit_mm as f64;
        if unit.is_nan() || unit <= 0.0 {
            return [0.0; 3];
        }
        self.radial[Self::exit_entry(r_mm, unit)][0].map(|x| half_value(half_bits(x)))
    }

    /// The entry of the exit tilt, the harmonics and the radial change nearest distance `r_mm` (L = `unit`).
    fn exit_entry(r_mm: f64, unit: f64) -> usize {
        ((r_mm / (r_mm + unit) * EXIT_TILT_ENTRIES as f64) as usize).min(EXIT_TILT_ENTRIES - 1)
    }

    pub fn texels(&self) -> Vec<[u32; 4]> {
        let header = std::iter::once([self.unit_mm.to_bits(), 0, 0, 0]);
        // Per node j of a side, `len` texels pairing nodes j − 1 (−1: flat) and j.
        let side = |nodes: &Vec<Vec<[f32; 3]>>, len: usize| -> Vec<[u32; 4]> {
            let flat = vec![[1.0f32; 3]; len];
            (0..curvature_profile::CURVATURE_NODES)
                .flat_map(|j| {
                    let lower = if j == 0 { &flat } else { &nodes[j - 1] };
                    let upper = &nodes[j];
                    (0..len)
                        .map(|i| {
                            let pair = |c: usize| half_bits(lower[i][c]) as u32 | (half_bits(upper[i][c]) as u32) << 16;
                            [pair(0), pair(1), pair(2), 0]
                        })
                        .collect::<Vec<_>>()
                })
                .collect()
        };
        let ratios = (0..curvature_profile::INCIDENCES).flat_map(|j| {
            side(&self.convex[j], CURVATURE_TABLE_ENTRIES)
                .into_iter()
                .chain(side(&self.concave[j], CURVATURE_TABLE_ENTRIES))
        });
        header
            .chain(ratios)
            .chain((0..curvature_profile::INCIDENCES).flat_map(|j| {
                [&self.convex_exit[j], &self.concave_exit[j], &self.convex_exit_far[j], &self.concave_exit_far[j]]
                    .into_iter()
                    .flat_map(|rows| side(rows, mc_profile::EXIT_BINS))
                    .collect::<Vec<_>>()
            }))
            .chain(self.exit_tilt.iter().chain(&self.harmonics).chain(&self.radial).map(|[a, b]| {
                let pair = |x: f32, y: f32| half_bits(x) as u32 | (half_bits(y) as u32) << 16;
                [pair(a[0], a[1]), pair(a[2], b[0]), pair(b[1], b[2]), 0]
            }))
            .collect()
    }

    /// The exit distribution's ratio per channel at exit cosine `cos_o` and curvature `kappa`
    /// (1/mm), as the shade pass reads it (`curvature_exit`): linear in cos²θo between bin
    /// centres (held beyond the outer ones), in κ as [`CurvatureRatios::lookup`], the rows of
    /// near and far light mixed by `far` (the share of the light from beyond a chord R√2), and
    /// linear in the light's mean sin²θi `sin2_i` between the rows of incidence.
    pub fn lookup_exit(&self, cos_o: f64, kappa: f64, far: f64, sin2_i: f64) -> [f64; 3] {
        let unit = self.unit_mm as f64;
        if unit.is_nan() || unit <= 0.0 {
            return [1.0; 3];
        }
        let y = (cos_o * cos_o * mc_profile::EXIT_BINS as f64 - 0.5).clamp(0.0, (mc_profile::EXIT_BINS - 1) as f64);
        let j = (y.floor() as usize).min(mc_profile::EXIT_BINS - 2);
        let (row, g) = curvature_profile::incidence_rows(sin2_i);
        [0, 1, 2].map(|c| {
            let at_incidence = |i: usize| {
                let (near_nodes, far_nodes) = if kappa < 0.0 {
                    (&self.concave_exit[i], &self.concave_exit_far[i])
                } else {
                    (&self.convex_exit[i], &self.convex_exit_far[i])
                };
                let read = |nodes: &[Vec<[f32; 3]>]| {
                    let at = |b: usize| self.between_nodes(nodes, kappa, b, c);
                    at(j) + (at(j + 1) - at(j)) * (y - j as f64)
                };
                let (near, beyond) = (read(near_nodes), read(far_nodes));
                near + (beyond - near) * far
            };
            let (a, b) = (at_incidence(row), at_incidence(row + 1));
            a + (b - a) * g
        })
    }

    /// Entry `i` of channel `c` of `nodes` (one side's rows) at curvature `kappa`, as the shade
    /// pass reads a paired texel: f16, linear between the two nodes of `curvature_profile::nodes_at`.
    fn between_nodes(&self, nodes: &[Vec<[f32; 3]>], kappa: f64, i: usize, c: usize) -> f64 {
        let (lower, upper, f) = curvature_profile::nodes_at(kappa * self.unit_mm as f64);
        let value = |v: f32| half_value(half_bits(v));
        let a = lower.map_or(1.0, |k| value(nodes[k][i][c]));
        a + (value(nodes[upper][i][c]) - a) * f
    }

    /// The ratio per channel at chord `r_mm` and curvature `kappa` (1/mm) of light that entered
    /// at sin²θi = `sin2_i` (per channel), as the shade pass reads it: the nearest entry, linear
    /// in κ from the flat surface to node 0 and in log κ between nodes, held past the last, and
    /// linear in sin²θi between the two rows of incidence around the channels' mean
    /// (curvature_profile::incidence_rows), each channel's weight clamped to them: two fetches,
    /// exact where the channels share their light's direction.
    pub fn lookup(&self, r_mm: f64, kappa: f64, sin2_i: [f64; 3]) -> [f64; 3] {
        let unit = self.unit_mm as f64;
        if unit.is_nan() || unit <= 0.0 {
            return [1.0; 3];
        }
        let rows = if kappa < 0.0 { &self.concave } else { &self.convex };
        let s = if kappa.is_nan() { 0.0 } else { r_mm * kappa.abs().min(curvature_profile::last_curvature(unit)) };
        let e = ((s / (s + 1.0) * CURVATURE_TABLE_ENTRIES as f64) as usize).min(CURVATURE_TABLE_ENTRIES - 1);
        // Two rows, around the channels' mean sin²θi (one light: each channel's own); each
        // channel's weight between them clamped (NaN: normal incidence).
        let q = sin2_i.map(|x| if x.is_nan() { 0.0 } else { x });
        let (j, _) = curvature_profile::incidence_rows((q[0] + q[1] + q[2]) / 3.0);
        let (lo, hi) = (curvature_profile::INCIDENCE_SIN2[j], curvature_profile::INCIDENCE_SIN2[j + 1]);
        [0, 1, 2].map(|c| {
            let g = ((q[c] - lo) / (hi - lo)).clamp(0.0, 1.0);
            let (a, b) = (self.between_nodes(&rows[j], kappa, e, c), self.between_nodes(&rows[j + 1], kappa, e, c));
            a + (b - a) * g
        })
    }

    /// Texels after the light across.
    pub const TEXELS: usize = 1
        + Self::ROWS * curvature_profile::INCIDENCES * (CURVATURE_TABLE_ENTRIES + 2 * mc_profile::EXIT_BINS)
        + 3 * EXIT_TILT_ENTRIES;
}

/// Beam diffusion's entry at `r` of a table of `reach`: Sd, but at r = 0 the v0 for which the
/// first interval [0, r1] with Sd = v0 + (v1 − v0)r/r1 holds ∫Sd dA of the disc r < r1:
/// π r1²(v0 + 2v1)/3 = that, so v0 = 3∫/(π r1²) − 2v1 (the map u = r/(r + reach) is linear in r to
/// 1/TABLE_SIZE there).
fn beam_diffusion_entry(b: &BeamMedium, reach: f64, r: f64) -> f64 {
    if r > 0.0 || !b.transports() {
        return beam_diffusion::sd(b, r);
    }
    let u1 = 1.0 / (TABLE_SIZE - 1) as f64;
    let r1 = reach * u1 / (1.0 - u1);
    let v1 = beam_diffusion::sd(b, r1);
    (3.0 * beam_diffusion::disc_integral(b, r1) / (std::f64::consts::PI * r1 * r1) - 2.0 * v1).max(v1)
}

/// 1/σtr where it is a length; 1 mm where no channel transports or none absorbs.
fn reach_of(sigma_tr: f64) -> f64 {
    if sigma_tr.is_finite() && sigma_tr > 0.0 {
        1.0 / sigma_tr
    } else {
        1.0
    }
}

/// IEEE binary16 bits of `x`, rounded to nearest even (GLSL's packHalf2x16 for these values).
fn half_bits(x: f32) -> u16 {
    let bits = x.to_bits();
    let sign = ((bits >> 16) & 0x8000) as u16;
    let exponent = ((bits >> 23) & 0xff) as i32 - 127 + 15;
    let mantissa = bits & 0x7f_ffff;
    if !x.is_finite() {
        return sign | 0x7c00 | if x.is_nan() { 0x200 } else { 0 };
    }
    if exponent >= 31 {
        return sign | 0x7c00;
    }
    let (kept, shift) = if exponent <= 0 {
        // A subnormal half: the implicit 1 joins the mantissa.
        if exponent < -10 {
            return sign;
        }
        (mantissa | 0x80_0000, (14 - exponent) as u32)
    } else {
        ((exponent as u32) << 23 | mantissa, 13)
    };
    let truncated = kept >> shift;
    let rest = kept & ((1 << shift) - 1);
    let halfway = 1 << (shift - 1);
    let up = rest > halfway || (rest == halfway && truncated & 1 == 1);
    sign | (truncated + up as u32) as u16
}

/// The value of IEEE binary16 bits (non-negative, finite here).
fn half_value(h: u16) -> f64 {
    let exponent = ((h >> 10) & 0x1f) as i32;
    let mantissa = (h & 0x3ff) as f64;
    let magnitude =
        if exponent == 0 { mantissa * 2f64.powi(-24) } else { (1.0 + mantissa / 1024.0) * 2f64.powi(exponent - 15) };
    // The sign bit (the exit tilt's g is negative near the entry; GLSL's unpackHalf2x16 keeps
    // it, and this mirror dropped it until the GPU cross-test, tests/bssrdf_gpu.rs).
    if h & 0x8000 != 0 {
        -magnitude
    } else {
        magnitude
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::materials::Material;
    use crate::physics::Diffusion;
    use dipole::sd;

    #[test]
    fn half_conversion_rounds_to_nearest() {
        for x in [0.0f32, 1.0, 0.5, 1e-3, 6.1e-5, 3e-6, 5.9604645e-8, 1e-9, 0.33333334, 0.9999] {
            for x in [x, -x] {
                let h = half_bits(x);
                let back = half_value(h);
                let ulp = if back.abs() < 6.1e-5 { 2f64.powi(-24) } else { back.abs() * 2f64.powi(-10) };
                assert!((back - x as f64).abs() <= 0.5 * ulp + 1e-30, "{x}: {back}");
            }
        }
        assert_eq!(half_value(0xbc00), -1.0);
        assert_eq!(half_bits(1.0), 0x3c00);
        assert_eq!(half_bits(0.5), 0x3800);
    }

    /// Against the closed form for every preset material, from r = 0 to where Sd has fallen
    /// below 1e-6 of its value at 0: within 1e-4 of Sd(0) absolute and 2e-3 relative.
    #[test]
    fn table_matches_the_closed_form() {
        for material in Material::presets() {
            let channels = [0, 1, 2].map(|c| material.channel(c).constants(Diffusion::Classical));
            let table = SdTable::dipole(&channels);
            for (c, constants) in channels.iter().enumerate() {
                if !constants.transports {
                    continue;
                }
                let at_zero = sd(constants, 0.0);
                let mut worst: f64 = 0.0;
                for k in 0..20_000 {
                    let r = table.reach * 40.0 * (k as f64 / 20_000.0).powi(2);
                    let exact = sd(constants, r);
                    if exact < 1e-6 * at_zero {
                        break;
                    }
                    let err = (table.lookup(r)[c] - exact).abs();
                    assert!(
                        err <= 1e-4 * at_zero + 2e-3 * exact,
                        "{} channel {c} r {r} mm: {} vs {exact}",
                        material.name,
                        table.lookup(r)[c]
                    );
                    worst = worst.max(err / exact);
                }
                assert!(worst < 2e-3, "{}: {worst}", material.name);
            }
        }
    }

    /// Photon beam diffusion's table against its f64 profile, for materials from skin to milk
    /// (g = 0.75, σt 20× σ't): within 2e-3 relative from the 16th entry on (nearer, the 1/r of
    /// single scattering bends too sharply for linear interpolation between entries, over a disc
    /// holding far below 1% of the light), to where Sd has fallen below 1e-6 of its value there;
    /// its plane integral ∫Sd dA within 0.2% of the profile's.
    #[test]
    fn beam_diffusion_table_matches_the_profile() {
        use crate::physics::halfspace::plane_integral;
        for name in ["skin1", "marble", "ketchup", "regularmilk", "espresso"] {
            let material = Material::find(name).unwrap();
            let media = [0, 1, 2].map(|c| BeamMedium::new(&material.channel(c)));
            let table = SdTable::beam_diffusion(&media);
            let first = 16.0 * table.reach / (TABLE_SIZE - 1) as f64;
            for (c, b) in media.iter().enumerate() {
                if !b.transports() {
                    continue;
                }
                let profile = |r: f64| beam_diffusion::sd(b, r);
                let start = profile(first);
                let mut worst: f64 = 0.0;
                for k in 0..1500 {
                    let r = first + table.reach * 40.0 * (k as f64 / 1500.0).powi(2);
                    let exact = profile(r);
                    if exact < 1e-6 * start {
                        break;
                    }
                    let rel = (table.lookup(r)[c] / exact - 1.0).abs();
                    assert!(rel <= 2e-3, "{name} channel {c} r {r} mm: {} vs {exact}", table.lookup(r)[c]);
                    worst = worst.max(rel);
                }
                let r_max = 60.0 / b.sigma_tr.max(1e-3 * b.sigma_t_reduced);
                let tabulated = plane_integral(|x| table.lookup(x.length())[c], 1e-6 * first, r_max, 1);
                let exact = plane_integral(|x| profile(x.length()), 1e-6 * first, r_max, 1);
                println!(
                    "{name} channel {c}: worst {worst:.1e} from entry 16; ∫Sd dA table / profile {:.5}",
                    tabulated / exact
                );
                assert!((tabulated / exact - 1.0).abs() < 2e-3, "{name} channel {c}: {tabulated} vs {exact}");
            }
        }
    }

    /// The slab's lookup as the shader reads it (f16 over a per-channel scale) against its f64
    /// values: within 1e-3 of each value from 1e-6 of the channel's peak on, and the texels lay
    /// entry i + 1 beside entry i.
    #[test]
    fn slab_lookup_keeps_its_values_in_f16() {
        let material = crate::materials::Material::find("skin1").unwrap();
        let channels = slab_profile::of_channels(&[0, 1, 2].map(|c| material.channel(c)));
        let gpu = SlabTransmission::monte_carlo(&channels);
        for (c, channel) in channels.iter().enumerate() {
            let peak = channel.lookup.iter().flatten().fold(0.0f64, |a, &b| a.max(b));
            assert!(peak > 0.0);
            for j in 0..slab_profile::LOOKUP_NODES {
                for i in 0..slab_profile::ENTRIES {
                    let (exact, got) = (channel.lookup[j][i], gpu.value(j, i, c));
                    if exact > 1e-6 * peak {
                        assert!((got / exact - 1.0).abs() < 1e-3, "channel {c} node {j} entry {i}: {got} vs {exact}");
                    }
                }
            }
        }
        let texels = gpu.texels();
        assert_eq!(texels.len(), SlabTransmission::TEXELS);
        let pair = texels[1 + 5]; // lookup node 0, entry 5
        assert_eq!(pair[0] & 0xffff, gpu.values[0][5][0] as u32);
        assert_eq!(pair[0] >> 16, gpu.values[0][6][0] as u32);
    }
}
