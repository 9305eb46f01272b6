//! The BSSRDF physics in f64: Fresnel, classical dipole, directional dipole.
