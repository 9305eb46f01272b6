//! `translucent compare A.exr B.exr`: A against the reference B (see src/compare.rs).

use crate::cli::CompareArgs;
use crate::compare::{compare as compare_images, report, write_error_image, CompareOptions};
use crate::error::Result;
use crate::runtime;

use super::check_output_path;

pub(super) fn compare(args: &CompareArgs) -> Result<i32> {
    if let Some(p) = &args.error_image {
        check_output_path(p, "--error-image", &["png"])?;
    }
    let options = CompareOptions { mask: args.mask.clone(), exposure: args.exposure, error_scale: args.error_scale };
    let (result, error_image) = compare_images(&args.a, &args.b, &options)?;
    if let Some(p) = &args.error_image {
        write_error_image(p, &error_image)?;
    }
    let mut text = if args.json {
        serde_json::to_string_pretty(&result).map_err(|e| runtime!("JSON: {e}"))? + "\n"
    } else {
        report(&result)
    };
    if let (Some(p), false) = (&args.error_image, args.json) {
        text += &format!(
            "error image: {} (max over channels of |A − B| / mean B, 0 … {})\n",
            p.display(),
            result.error_scale
        );
    }
    crate::error::write_stdout(&text)?;
    Ok(0)
}
