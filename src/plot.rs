//! `translucent profile`: Sd against distance in the plane of incidence, per RGB channel, for
//! both models and several angles of incidence — how researchers look at a material.
//!
//! Geometry: a flat surface z = 0 with normal +z, light entering at the origin from direction
//! ωi tilted by θ toward −x, exit points at (±r, 0, 0): + is the forward side (where the refracted
//! light travels), − the backward side.

use std::path::Path;

use glam::DVec3;
use plotters::prelude::*;

use crate::error::Result;
use crate::materials::Material;
use crate::physics::{Diffusion, Model, Query};
use crate::{bad_input, runtime};

/// The distances a profile may span, in mm.
pub const R_LIMITS_MM: (f64, f64) = (1e-9, 1e9);

/// The values a log axis shows: Sd outside this (zero, subnormal, overflowing) is left out.
const SD_PLOTTABLE: (f64, f64) = (1e-290, 1e290);

pub struct ProfileSpec {
    pub material: Material,
    pub models: Vec<Model>,
    pub angles_deg: Vec<f64>,
    pub r_min_mm: f64,
    pub r_max_mm: f64,
    pub diffusion: Diffusion,
    pub samples: usize,
}

/// One curve: a model, an angle, a side (+1 forward, −1 backward), a channel.
pub struct Curve {
    pub model: Model,
    pub angle_deg: f64,
    pub side: f64,
    pub channel: usize,
    pub points: Vec<(f64, f64)>,
}

impl ProfileSpec {
    pub fn validate(&self) -> Result<()> {
        self.material.validate()?;
        if !(self.r_min_mm > 0.0 && self.r_max_mm > self.r_min_mm && self.r_max_mm.is_finite()) {
            return Err(bad_input!(
                "--r-min/--r-max: need 0 < r-min < r-max, got {} and {}",
                self.r_min_mm,
                self.r_max_mm
            ));
        }
        // A log axis over more decades than this has nothing to show and makes the plotting
        // library's tick search crawl.
        if self.r_min_mm < R_LIMITS_MM.0 || self.r_max_mm > R_LIMITS_MM.1 {
            return Err(bad_input!(
                "--r-min/--r-max: {:e} and {:e} mm: both must be within [{:e}, {:e}] mm",
                self.r_min_mm,
                self.r_max_mm,
                R_LIMITS_MM.0,
                R_LIMITS_MM.1
            ));
        }
        if let Some(a) = self.angles_deg.iter().find(|a| !(0.0..90.0).contains(*a)) {
            return Err(bad_input!("--angles: {a} must be in [0, 90) degrees"));
        }
        if self.samples < 2 || self.samples > 100_000 {
            return Err(bad_input!("--samples {}: must be between 2 and 100000", self.samples));
        }
        Ok(())
    }

    pub fn curves(&self) -> Vec<Curve> {
        let mut curves = Vec::new();
        let (lo, hi) = (self.r_min_mm.ln(), self.r_max_mm.ln());
        for &model in &self.models {
            for &angle in &self.angles_deg {
                let t = angle.to_radians();
                let wi = DVec3::new(-t.sin(), 0.0, t.cos());
                for side in [1.0, -1.0] {
                    for channel in 0..3 {
                        let medium = self.material.channel(channel);
                        let points = (0..self.samples)
                            .map(|k| {
                                let r = (lo + (hi - lo) * k as f64 / (self.samples - 1) as f64).exp();
                                let q = Query {
                                    medium,
                                    xi: DVec3::ZERO,
                                    ni: DVec3::Z,
                                    wi,
                                    xo: DVec3::new(side * r, 0.0, 0.0),
                                    no: DVec3::Z,
                                };
                                (r, q.sd(model, self.diffusion))
                            })
                            .collect();
                        curves.push(Curve { model, angle_deg: angle, side, channel, points });
                    }
                }
            }
        }
        curves
    }
}

fn model_name(m: Model) -> &'static str {
    m.name()
}

/// Writes the plot by extension: `.png`, `.svg` or `.csv`.
pub fn write_profile(spec: &ProfileSpec, path: &Path) -> Result<()> {
    spec.validate()?;
    let ext = path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()).unwrap_or_default();
    let curves = spec.curves();
    if !matches!(ext.as_str(), "csv" | "svg" | "png") {
        return Err(bad_input!("--out {}: use .png, .svg or .csv", path.display()));
    }
    if ext == "csv" {
        return write_csv(&curves, path);
    }
    if !curves.iter().flat_map(|c| &c.points).any(|p| plottable(p.1)) {
        return Err(bad_input!(
            "--out {}: Sd is zero (or outside [{:e}, {:e}]) at every distance for {} (σs = 0, or coefficients \
             too small?): nothing to draw on a log axis; a .csv output lists the values",
            path.display(),
            SD_PLOTTABLE.0,
            SD_PLOTTABLE.1,
            spec.material.name
        ));
    }
    // Both backends lay text out with the font (SVG too, to measure it).
    register_font()?;
    const SIZE: (u32, u32) = (1100, 700);
    // Drawn in memory and written in one checked write (plotters' own file output can lose an
    // error such as a full disk).
    let bytes = if ext == "svg" {
        let mut svg = String::new();
        draw(spec, &curves, SVGBackend::with_string(&mut svg, SIZE).into_drawing_area())?;
        svg.into_bytes()
    } else {
        let mut rgb = vec![0u8; (SIZE.0 * SIZE.1 * 3) as usize];
        draw(spec, &curves, BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area())?;
        let img = image::RgbImage::from_raw(SIZE.0, SIZE.1, rgb).ok_or_else(|| runtime!("plot: buffer size"))?;
        crate::output::encode(img, image::ImageFormat::Png)?
    };
    crate::output::write_file(path, &bytes).map_err(|e| runtime!("--out: {e}"))
}

fn plottable(v: f64) -> bool {
    v.is_finite() && v >= SD_PLOTTABLE.0 && v <= SD_PLOTTABLE.1
}

fn write_csv(curves: &[Curve], path: &Path) -> Result<()> {
    let mut text = String::from("r_mm,side,model,theta_deg,channel,sd\n");
    for c in curves {
        let side = if c.side > 0.0 { "forward" } else { "backward" };
        for (r, sd) in &c.points {
            text +=
                &format!("{r},{side},{},{},{},{sd}\n", model_name(c.model), c.angle_deg, ["r", "g", "b"][c.channel]);
        }
    }
    crate::output::write_file(path, text.as_bytes()).map_err(|e| runtime!("--out: {e}"))
}

pub(crate) fn register_font() -> Result<()> {
    static FONT: &[u8] = include_bytes!("../assets/fonts/DejaVuSans.ttf");
    plotters::style::register_font("sans-serif", FontStyle::Normal, FONT)
        .map_err(|_| runtime!("the embedded font could not be read"))
}

fn draw<DB: DrawingBackend>(
    spec: &ProfileSpec,
    curves: &[Curve],
    root: DrawingArea<DB, plotters::coord::Shift>,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| runtime!("plot: {e}");
    root.fill(&WHITE).map_err(err)?;
    // The caller checked that some value is plottable; the axis spans at most 12 decades.
    let positive = curves.iter().flat_map(|c| c.points.iter().map(|p| p.1)).filter(|v| plottable(*v));
    let max = positive.clone().fold(SD_PLOTTABLE.0, f64::max);
    let min = positive.fold(max, f64::min).max(max * 1e-12);
    let title = format!("{}: Sd vs distance in the plane of incidence (η = {})", spec.material.name, spec.material.eta);
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 24))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(80)
        .build_cartesian_2d((spec.r_min_mm..spec.r_max_mm).log_scale(), (min * 0.5..max * 2.0).log_scale())
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("distance r from the point of entry [mm]")
        .y_desc("Sd [1/mm²]")
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .label_style(("sans-serif", 15))
        .draw()
        .map_err(err)?;
    let colours = [RGBColor(200, 30, 30), RGBColor(30, 150, 40), RGBColor(40, 60, 210)];
    for c in curves {
        let colour = colours[c.channel];
        // Solid: forward side; lighter: backward. Thick: directional dipole; thin: classical.
        let shade = if c.side > 0.0 { colour.mix(1.0) } else { colour.mix(0.4) };
        let width = if c.model == Model::Directional { 2 } else { 1 };
        let points = c.points.iter().filter(|p| plottable(p.1)).copied();
        let series = chart.draw_series(LineSeries::new(points, shade.stroke_width(width))).map_err(err)?;
        if c.channel == 0 {
            let side = if c.side > 0.0 { "forward" } else { "backward" };
            let label = format!("{} θi={}° {side}", model_name(c.model), c.angle_deg);
            series
                .label(label)
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], shade.stroke_width(width)));
        }
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(err)?;
    root.present().map_err(err)?;
    Ok(())
}

/// One line of the albedo plot: a label, a colour, whether it is drawn as points (the path
/// tracer) or a line, and its (α', total diffuse reflectance) pairs.
pub struct AlbedoSeries {
    pub label: String,
    pub colour: RGBColor,
    pub points_only: bool,
    pub points: Vec<(f64, f64)>,
}

/// The thick slab's total diffuse reflectance against the reduced albedo (light at normal
/// incidence), one series per model and the path tracer's points, as a PNG.
pub fn write_albedo_plot(title: &str, series: &[AlbedoSeries], path: &Path) -> Result<()> {
    register_font()?;
    const SIZE: (u32, u32) = (1100, 700);
    let mut rgb = vec![0u8; (SIZE.0 * SIZE.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area();
        let err = |e: DrawingAreaErrorKind<_>| runtime!("plot: {e}");
        root.fill(&WHITE).map_err(err)?;
        let y_max = series.iter().flat_map(|s| s.points.iter().map(|p| p.1)).fold(1.0f64, f64::max) * 1.05;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(0.3f64..1.0f64, 0.0f64..y_max)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("reduced albedo α' = σ's/σ't")
            .y_desc("total diffuse reflectance")
            .label_style(("sans-serif", 15))
            .draw()
            .map_err(err)?;
        for s in series {
            let colour = s.colour;
            if s.points_only {
                chart
                    .draw_series(s.points.iter().map(|&p| Circle::new(p, 4, colour.filled())))
                    .map_err(err)?
                    .label(s.label.clone())
                    .legend(move |(x, y)| Circle::new((x + 10, y), 4, colour.filled()));
            } else {
                chart
                    .draw_series(LineSeries::new(s.points.iter().copied(), colour.stroke_width(2)))
                    .map_err(err)?
                    .label(s.label.clone())
                    .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], colour.stroke_width(2)));
            }
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 15))
            .position(SeriesLabelPosition::UpperLeft)
            .draw()
            .map_err(err)?;
        root.present().map_err(err)?;
    }
    let img = image::RgbImage::from_raw(SIZE.0, SIZE.1, rgb).ok_or_else(|| runtime!("plot: buffer size"))?;
    let bytes = crate::output::encode(img, image::ImageFormat::Png)?;
    crate::output::write_file(path, &bytes).map_err(|e| runtime!("--out: {e}"))
}
