//! `translucent bssrdf`: Sd for CSV rows on stdin, in f64 on the CPU or f32 on the GPU.

use crate::cli::BssrdfArgs;
use crate::error::Result;
use crate::physics::Diffusion;
use crate::vk::Context;
use crate::{bad_input, runtime};

pub(super) fn bssrdf(args: &BssrdfArgs) -> Result<i32> {
    use std::io::Write;
    let (model, diffusion) = (args.model, Diffusion::from(args.diffusion));
    let gpu = if args.gpu {
        let ctx = Context::new(&args.device.options())?;
        let pass = crate::passes::bssrdf_eval::BssrdfEvalPass::new(&ctx)?;
        Some((ctx, pass))
    } else {
        None
    };
    // Streamed: a batch of rows is read, evaluated and written before the next is read, so memory
    // stays bounded and output starts at once, whatever the input's length.
    let stdin = std::io::stdin();
    let mut reader = crate::bssrdf_csv::Reader::new(stdin.lock());
    let mut out = std::io::BufWriter::with_capacity(1 << 16, std::io::stdout().lock());
    let start = std::time::Instant::now();
    let mut rows = 0usize;
    let mut header_written = false;
    loop {
        let batch = reader.next_batch(crate::bssrdf_csv::BATCH_ROWS)?;
        if !header_written {
            crate::bssrdf_csv::write_header(&mut out)?;
            header_written = true;
        }
        if batch.is_empty() {
            break;
        }
        let queries: Vec<crate::physics::Query> = batch.iter().map(|(_, q)| *q).collect();
        let sd: Vec<f64> = match &gpu {
            Some((ctx, pass)) => {
                for (line, q) in &batch {
                    crate::bssrdf_csv::gpu_range_check(q).map_err(|why| {
                        bad_input!(
                            "bssrdf --gpu: line {line}: {why}; the GPU evaluates in f32 (leave out --gpu to use f64)"
                        )
                    })?;
                }
                let sd = pass.evaluate(ctx, &queries, model, diffusion)?;
                if let Some(i) = sd.iter().position(|v| !v.is_finite()) {
                    return Err(runtime!(
                        "bssrdf --gpu: line {}: the GPU returned {} (f32 overflow)",
                        batch[i].0,
                        sd[i]
                    ));
                }
                sd.into_iter().map(f64::from).collect()
            }
            None => queries.iter().map(|q| q.sd(model, diffusion)).collect(),
        };
        crate::bssrdf_csv::write_rows(&mut out, &queries, &sd)?;
        out.flush().map_err(|e| runtime!("stdout: {e}"))?;
        rows += queries.len();
    }
    out.flush().map_err(|e| runtime!("stdout: {e}"))?;
    log::info!("evaluated {rows} rows in {:.3} s", start.elapsed().as_secs_f64());
    Ok(match gpu {
        Some((ctx, pass)) => {
            let (counts, validating) = (ctx.validation_counts(), ctx.validation);
            drop(pass);
            drop(ctx);
            counts.exit_code(validating)
        }
        None => 0,
    })
}
