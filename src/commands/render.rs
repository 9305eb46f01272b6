//! `translucent render`: frames to an image file (or one per frame), with the GPU timings.

use crate::cli::RenderArgs;
use crate::error::Result;
use crate::frame::Renderer;
use crate::profiling::ProfileReport;
use crate::runtime;
use crate::settings::{RenderSettings, SceneSettings};
use crate::vk::Context;

use super::{check_output_path, frame_path};

pub(super) fn render(args: &RenderArgs) -> Result<i32> {
    // Check everything the user typed before the (slow) device start.
    if let Some(scene) = &args.scene {
        let argv: Vec<String> = std::env::args().collect();
        let (args, settings) =
            crate::settings::scene_file_settings(scene, args, &|f| crate::pbrt::flag_given(&argv, f))?;
        return render_settings(&args, settings);
    }
    render_settings(args, RenderSettings::from_args(args)?)
}

fn render_settings(args: &RenderArgs, settings: RenderSettings) -> Result<i32> {
    check_output_path(&args.out, "--out", &["png", "exr"])?;
    if let Some(p) = &args.profile_out {
        check_output_path(p, "--profile-out", &["json"])?;
    }
    let RenderSettings { mut world, mut desc, profile } = settings;
    let ctx = Context::new(&args.device.options())?;
    let counts = ctx.validation_counts();
    let validating = ctx.validation;
    let device_name = format!("{} ({})", ctx.info.name, ctx.info.driver);
    let mut renderer = Renderer::new(ctx, profile)?;
    // A progress bar over the shading of every frame; indicatif hides it off a terminal.
    let bar = indicatif::ProgressBar::new(Renderer::progress_length(args.frames));
    bar.set_style(
        indicatif::ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {percent}% of {msg}, {eta} left")
            .map_err(|e| runtime!("progress bar: {e}"))?
            .progress_chars("=> "),
    );
    bar.set_message(format!("{} frame(s)", args.frames));
    renderer.progress = Some(bar.clone());

    let every_frame = args.out.to_string_lossy().contains("{frame}");
    let mesh_spec = SceneSettings::from_args(args).mesh_spec();
    // The first translucent object is the one animated (a world of opaque objects only has none).
    let first_mesh = match world.objects.first() {
        Some(o) => o.mesh.clone(),
        None if args.deform.is_some() => {
            return Err(crate::bad_input!("--deform: the scene has no translucent object"))
        }
        None => world.opaque[0].mesh.clone(),
    };
    let animation = crate::deform::Animation::new(&mesh_spec, &first_mesh, args.deform, args.deform_period, args.up)?;
    let base_lights = desc.lights.clone();
    let (centre, _) = crate::scene::bounding_sphere(&first_mesh.positions);
    let mut frames = Vec::new();
    for index in 0..args.frames {
        let angle = (args.spin_light * index as f32).to_radians();
        desc.lights = base_lights.iter().map(|l| l.rotated(args.up, angle, centre)).collect();
        if let Some(animation) = animation.as_ref().filter(|_| index > 0) {
            world.objects[0].mesh = animation.mesh(index)?;
        }
        frames.push(renderer.render_frame(&world, &desc)?);
        if every_frame {
            let path = frame_path(&args.out, index);
            renderer.write_image(&path)?;
            bar.suspend(|| crate::note!("wrote {}", path.display()));
        }
    }
    bar.finish_and_clear();
    if !every_frame {
        if args.width as u64 * args.height as u64 >= 1 << 22 {
            // Encoding a large image takes seconds after the bar is gone: say what is happening.
            crate::note!("writing {} ({}x{})…", args.out.display(), args.width, args.height);
        }
        renderer.write_image(&args.out)?;
        crate::note!("wrote {} ({}x{}, {} frame(s))", args.out.display(), args.width, args.height, args.frames);
    }
    let work = renderer.work()?;
    let per_object = renderer.work_per_object()?;
    drop(renderer);

    if frames.iter().any(|f| !f.is_empty()) {
        let report = ProfileReport::from_frames(&device_name, frames);
        crate::error::write_stdout(&crate::profiling::format_table(&report))?;
        if let Some(path) = &args.profile_out {
            crate::output::write_file(path, crate::profiling::chrome_trace_json(&report).as_bytes())
                .map_err(|e| runtime!("--profile-out: {e}"))?;
        }
    }
    if args.profile && work.pixels > 0 {
        let per_pixel = |sum: u32| sum as f64 / work.pixels as f64;
        crate::error::write_stdout(&format!(
            "work per pixel (last frame, {} pixels): nodes visited mean {:.1} max {}, points evaluated mean {:.1} max {}, Sd evaluations mean {:.1}\n",
            work.pixels,
            per_pixel(work.node_sum),
            work.node_max,
            per_pixel(work.point_sum),
            work.point_max,
            per_pixel(work.evaluation_sum)
        ))?;
        if per_object.len() > 1 {
            for (k, w) in per_object.iter().enumerate() {
                let px = w.pixels.max(1) as f64;
                crate::error::write_stdout(&format!(
                    "  object {k} ({} pixels): nodes visited mean {:.1} max {}, points evaluated mean {:.1} max {}, Sd evaluations mean {:.1}\n",
                    w.pixels,
                    w.node_sum as f64 / px,
                    w.node_max,
                    w.point_sum as f64 / px,
                    w.point_max,
                    w.evaluation_sum as f64 / px
                ))?;
            }
        }
    }
    Ok(counts.exit_code(validating))
}
