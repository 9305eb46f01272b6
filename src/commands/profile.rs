//! `translucent profile`: Sd against distance per channel, plotted or as CSV.

use crate::cli::ProfileArgs;
use crate::error::Result;
use crate::physics::Diffusion;

use super::check_output_path;

pub(super) fn profile(args: &ProfileArgs) -> Result<i32> {
    check_output_path(&args.out, "--out", &["png", "svg", "csv"])?;
    let material = args.material.material()?;
    let r_max = match args.r_max {
        Some(r) => r,
        None => {
            // Ten diffusion lengths 1/σtr of the channel that dies out first.
            let sigma_tr = (0..3)
                .map(|ch| material.channel(ch).constants(Diffusion::from(args.diffusion)))
                .filter(|c| c.transports)
                .map(|c| c.sigma_tr)
                .fold(0.0f64, f64::max);
            if sigma_tr > 0.0 {
                (10.0 / sigma_tr).min(1000.0)
            } else {
                100.0
            }
        }
    };
    let spec = crate::plot::ProfileSpec {
        material,
        models: args.model.clone(),
        angles_deg: args.angles.clone(),
        r_min_mm: args.r_min,
        r_max_mm: r_max,
        diffusion: args.diffusion.into(),
        samples: args.samples,
    };
    crate::plot::write_profile(&spec, &args.out)?;
    crate::note!("wrote {}", args.out.display());
    Ok(0)
}
