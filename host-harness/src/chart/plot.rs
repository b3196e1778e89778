//! The charts of `palpate chart`, drawn with `plotters` in SVG and PNG
//! (the PNG encoded by the `png` crate), text in DejaVu Sans embedded in
//! the binary (`assets/fonts`, Bitstream Vera licence): rasterized in the
//! PNGs, glyph outlines in the SVGs ([`super::svg_text`]), so neither needs
//! a font where it is viewed. Files are written atomically.

use std::path::Path;
use std::sync::Once;

use anyhow::Context;
use plotters::coord::Shift;
use plotters::prelude::*;

use palpate_kernel::tensor_mass::Integrator;

use super::body::Load;
use super::memory::{ERROR_FLOOR, MemoryError, MemoryPoint};
use super::model::Model;
use super::results::Study;
use super::select::pareto_front;
use super::series::{Against, cost_series, log_slope, points, trajectory_points};
use super::stability::{Map, Outcome};
use crate::experiment::volume_bend::{Protocol, SceneResult};
use crate::output::atomic::write_file;

/// DejaVu Sans, registered as plotters' `sans-serif`.
static FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");
/// Chart size, px.
const SIZE: (u32, u32) = (800, 560);

fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The embedded font parses (checked by the chart tests).
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// Error type of the drawing calls.
type Drawn = anyhow::Result<()>;

/// Draws `chart` into `dir/name.svg` and `dir/name.png`.
macro_rules! render {
    ($dir:expr, $name:expr, $chart:expr) => {{
        register_font();
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
            $chart(&root)?;
            root.present().map_err(|e| anyhow::anyhow!("{e}"))?;
        }
        let svg = super::svg_text::outline_text(&svg, FONT)?;
        write_file(&$dir.join(format!("{}.svg", $name)), svg.as_bytes())?;
        let mut rgb = vec![0u8; (SIZE.0 * SIZE.1 * 3) as usize];
        {
            let root = BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area();
            $chart(&root)?;
            root.present().map_err(|e| anyhow::anyhow!("{e}"))?;
        }
        write_file(&$dir.join(format!("{}.png", $name)), &encode_png(&rgb)?)?;
        Ok::<(), anyhow::Error>(())
    }};
}

/// PNG bytes of an RGB buffer of [`SIZE`].
fn encode_png(rgb: &[u8]) -> anyhow::Result<Vec<u8>> {
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, SIZE.0, SIZE.1);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().context("png header")?;
    writer.write_image_data(rgb).context("png data")?;
    writer.finish().context("png end")?;
    Ok(out)
}

fn err(e: impl core::fmt::Display) -> anyhow::Error {
    anyhow::anyhow!("drawing: {e}")
}

/// A colour per model.
pub fn model_colour(model: Model) -> RGBColor {
    match model {
        Model::PrecomputedLinear => RGBColor(31, 119, 180),
        Model::PrecomputedQuasi => RGBColor(23, 190, 207),
        Model::TensorMassLinear => RGBColor(255, 127, 14),
        Model::Stvk => RGBColor(214, 39, 40),
        Model::StvkPenalty => RGBColor(44, 160, 44),
        Model::Corotational => RGBColor(140, 86, 75),
        Model::NeoHookean => RGBColor(227, 119, 194),
        Model::Hybrid => RGBColor(148, 103, 189),
    }
}

/// `[lo, hi]` widened by a factor for a log axis, from positive values.
fn log_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if lo.is_finite() {
        (lo / 2.0, hi * 2.0)
    } else {
        (1e-6, 1.0)
    }
}

/// The file names of the charts written, without extension.
pub fn draw_all(
    study: &Study,
    volume: &[SceneResult],
    dir: &Path,
    loads: &[Load],
    levels: &[f64],
) -> anyhow::Result<Vec<String>> {
    let mut names = Vec::new();
    for &load in loads {
        for &level in levels {
            let name = format!("pareto-{}-{}", load.name(), (100.0 * level).round());
            render!(dir, name, |root: &DrawingArea<_, Shift>| pareto(
                root, study, load, level
            ))?;
            names.push(name);
        }
    }
    for &load in loads {
        if !study.trajectories.iter().any(|t| t.load == load) {
            continue;
        }
        let name = format!("trajectory-{}", load.name());
        render!(dir, name, |root: &DrawingArea<_, Shift>| trajectory_chart(
            root, study, load
        ))?;
        names.push(name);
    }
    render!(dir, "cost-mesh", |root: &DrawingArea<_, Shift>| cost_mesh(
        root, study
    ))?;
    names.push("cost-mesh".into());
    for map in &study.stability {
        let name = match map.model {
            Model::Stvk => format!("stability-{}", map.integrator),
            model => format!("stability-{}-{}", model.name(), map.integrator),
        };
        render!(dir, name, |root: &DrawingArea<_, Shift>| stability(
            root, map
        ))?;
        names.push(name);
    }
    if !volume.is_empty() {
        render!(dir, "volume", |root: &DrawingArea<_, Shift>| volume_chart(
            root, volume
        ))?;
        names.push("volume".into());
    }
    if !study.memory.is_empty() {
        for error in MemoryError::ALL {
            render!(dir, error.chart(), |root: &DrawingArea<_, Shift>| {
                memory_chart(root, &study.memory, error)
            })?;
            names.push(error.chart().into());
        }
    }
    Ok(names)
}

/// A chart with both axes logarithmic.
type LogChart<'a, DB> = ChartContext<'a, DB, Cartesian2d<LogCoord<f64>, LogCoord<f64>>>;

/// A log-log chart over `points` (both axes' ranges from them): `caption`, the axes'
/// descriptions `axes` (x, y), tick labels as powers of ten.
fn log_frame<'a, DB: DrawingBackend>(
    root: &'a DrawingArea<DB, Shift>,
    caption: &str,
    axes: [&str; 2],
    points: impl Iterator<Item = (f64, f64)> + Clone,
) -> anyhow::Result<LogChart<'a, DB>> {
    let x = log_range(points.clone().map(|p| p.0));
    let y = log_range(points.map(|p| p.1));
    let mut chart = ChartBuilder::on(root)
        .caption(caption, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d((x.0..x.1).log_scale(), (y.0..y.1).log_scale())
        .map_err(err)?;
    let [x_desc, y_desc] = axes;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .x_label_formatter(&|v| format!("{v:.0e}"))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()
        .map_err(err)?;
    Ok(chart)
}

/// Every chart's legend: its series' labels on a translucent white box at `position`.
fn legend<'a, DB: DrawingBackend + 'a, X: Ranged, Y: Ranged>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<X, Y>>,
    position: SeriesLabelPosition,
) -> Drawn {
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .position(position)
        .label_font(("sans-serif", 13))
        .draw()
        .map_err(err)?;
    Ok(())
}

/// The frame of an error-against-cost chart: log axes over `points`
/// (`axes`: the x and y descriptions) and the Pareto front (`front`, one
/// flag per point) joined by a line in the legend.
fn pareto_frame<'a, DB: DrawingBackend>(
    root: &'a DrawingArea<DB, Shift>,
    caption: &str,
    axes: [&str; 2],
    points: &[(f64, f64)],
    front: &[bool],
) -> anyhow::Result<LogChart<'a, DB>> {
    let mut chart = log_frame(root, caption, axes, points.iter().copied())?;
    let mut on_front: Vec<(f64, f64)> = points
        .iter()
        .zip(front)
        .filter(|(_, f)| **f)
        .map(|(p, _)| *p)
        .collect();
    on_front.sort_by(|a, b| a.0.total_cmp(&b.0));
    chart
        .draw_series(LineSeries::new(on_front, BLACK.stroke_width(1)))
        .map_err(err)?
        .label("Pareto front")
        .legend(|(x, y)| PathElement::new([(x, y), (x + 16, y)], BLACK));
    Ok(chart)
}

/// Error (tip, against the converged neo-Hookean truth, or against the
/// Newton St Venant-Kirchhoff reference where the truth did not converge,
/// as the axis says) against time per step for one load and level, every
/// mesh and model; the Pareto front filled and joined.
fn pareto<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    study: &Study,
    load: Load,
    level: f64,
) -> Drawn {
    root.fill(&WHITE).map_err(err)?;
    let (mut runs, mut points) = points(study, load, level, Against::Truth);
    let mut axis = "tip displacement error vs neo-Hookean truth";
    if runs.is_empty() {
        (runs, points) = super::series::points(study, load, level, Against::Stvk);
        axis = "tip error vs Newton StVK (no converged neo-Hookean truth)";
    }
    let points: Vec<(f64, f64)> = points.into_iter().map(|(c, e)| (c, e.max(1e-6))).collect();
    let front = pareto_front(&points);
    let caption = format!(
        "{} at {:.0} % of the height: error vs time per step",
        load.name(),
        100.0 * level
    );
    let axes = ["time per step, s (f64)", axis];
    let mut chart = pareto_frame(root, &caption, axes, &points, &front)?;
    for model in Model::ALL {
        let colour = model_colour(model);
        let series: Vec<_> = runs
            .iter()
            .zip(&points)
            .zip(&front)
            .filter(|((r, _), _)| r.model == model)
            .map(|((r, p), f)| (*p, *f, r.mesh.clone()))
            .collect();
        chart
            .draw_series(series.into_iter().map(|(p, f, mesh)| {
                let style = if f {
                    colour.filled()
                } else {
                    colour.stroke_width(2)
                };
                EmptyElement::at(p)
                    + Circle::new((0, 0), 6, style)
                    + Text::new(mesh, (8, -6), ("sans-serif", 11))
            }))
            .map_err(err)?
            .label(model.name())
            .legend(move |(x, y)| Circle::new((x + 8, y), 5, colour.filled()));
    }
    legend(&mut chart, SeriesLabelPosition::LowerLeft)?;
    Ok(())
}

/// A colour per integrator (by its CLI name).
fn integrator_colour(name: &str) -> RGBColor {
    match name {
        "euler" => RGBColor(214, 39, 40),
        "symplectic" => RGBColor(31, 119, 180),
        "rk4" => RGBColor(44, 160, 44),
        _ => RGBColor(148, 103, 189),
    }
}

/// The trajectory error against the compute time per simulated second
/// for one load: colour by integrator, shape by model (circle linear,
/// triangle St Venant-Kirchhoff, square with the penalty), the Pareto
/// front joined. Diverged runs have no point (the report lists them).
fn trajectory_chart<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    study: &Study,
    load: Load,
) -> Drawn {
    root.fill(&WHITE).map_err(err)?;
    let (runs, points) = trajectory_points(study, load);
    let front = pareto_front(&points);
    let level = runs.first().map_or(0.0, |t| t.level);
    let caption = format!(
        "{} at {:.0} %: trajectory error vs Δt/16, against cost",
        load.name(),
        100.0 * level
    );
    let axes = [
        "compute time per simulated second, s (f64)",
        "trajectory error (relative L2, max over time)",
    ];
    let mut chart = pareto_frame(root, &caption, axes, &points, &front)?;
    for integrator in Integrator::ALL.map(Integrator::name) {
        let colour = integrator_colour(integrator);
        let series: Vec<_> = runs
            .iter()
            .zip(&points)
            .zip(&front)
            .filter(|((t, _), _)| t.integrator == integrator)
            .map(|((t, p), f)| (*p, *f, t.model, t.mesh.clone()))
            .collect();
        let label = if series.is_empty() {
            format!("{integrator} (no run within its limit)")
        } else {
            integrator.to_string()
        };
        chart
            .draw_series(series.into_iter().map(|(p, f, model, mesh)| {
                let style = if f {
                    colour.filled()
                } else {
                    colour.stroke_width(2)
                };
                let marker: DynElement<'static, DB, (i32, i32)> = match model {
                    Model::Stvk => TriangleMarker::new((0, 0), 7, style).into_dyn(),
                    Model::StvkPenalty => Rectangle::new([(-5, -5), (5, 5)], style).into_dyn(),
                    Model::Hybrid => Cross::new((0, 0), 5, colour.stroke_width(2)).into_dyn(),
                    _ => Circle::new((0, 0), 5, style).into_dyn(),
                };
                EmptyElement::at(p) + marker + Text::new(mesh, (8, -6), ("sans-serif", 11))
            }))
            .map_err(err)?
            .label(label)
            .legend(move |(x, y)| Circle::new((x + 8, y), 5, colour.filled()));
    }
    // The shapes' legend (no points of their own).
    let grey = RGBColor(120, 120, 120);
    let none = || core::iter::empty::<Circle<(f64, f64), i32>>();
    chart
        .draw_series(none())
        .map_err(err)?
        .label(Model::TensorMassLinear.name())
        .legend(move |(x, y)| Circle::new((x + 8, y), 5, grey.stroke_width(2)));
    chart
        .draw_series(none())
        .map_err(err)?
        .label(Model::Stvk.name())
        .legend(move |(x, y)| TriangleMarker::new((x + 8, y), 7, grey.stroke_width(2)));
    chart
        .draw_series(none())
        .map_err(err)?
        .label(Model::StvkPenalty.name())
        .legend(move |(x, y)| {
            Rectangle::new([(x + 3, y - 5), (x + 13, y + 5)], grey.stroke_width(2))
        });
    chart
        .draw_series(none())
        .map_err(err)?
        .label(Model::Hybrid.name())
        .legend(move |(x, y)| Cross::new((x + 8, y), 5, grey.stroke_width(2)));
    legend(&mut chart, SeriesLabelPosition::LowerLeft)?;
    Ok(())
}

/// Time per step against vertices, log-log, slope in the legend.
fn cost_mesh<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, study: &Study) -> Drawn {
    root.fill(&WHITE).map_err(err)?;
    let series: Vec<(Model, Vec<(f64, f64)>)> = Model::ALL
        .iter()
        .map(|&m| (m, cost_series(study, m)))
        .collect();
    let x = log_range(series.iter().flat_map(|s| s.1.iter().map(|p| p.0)));
    let y = log_range(series.iter().flat_map(|s| s.1.iter().map(|p| p.1)));
    let mut chart = ChartBuilder::on(root)
        .caption(
            "cost against mesh size (median over loads)",
            ("sans-serif", 20),
        )
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d((x.0..x.1).log_scale(), (y.0..y.1).log_scale())
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_labels(6)
        .x_desc("vertices")
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_desc("time per step, s (f64)")
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()
        .map_err(err)?;
    for (model, points) in series {
        let colour = model_colour(model);
        let slope = log_slope(&points);
        chart
            .draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))
            .map_err(err)?
            .label(format!("{} (slope {slope:.2})", model.name()))
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 16, y)], colour));
        chart
            .draw_series(
                points
                    .into_iter()
                    .map(|p| Circle::new(p, 4, colour.filled())),
            )
            .map_err(err)?;
    }
    legend(&mut chart, SeriesLabelPosition::UpperLeft)?;
    Ok(())
}

/// Colour of a stability outcome.
fn outcome_colour(outcome: Outcome) -> RGBColor {
    match outcome {
        Outcome::Stable => RGBColor(44, 160, 44),
        Outcome::Diverged => RGBColor(214, 39, 40),
        Outcome::Inverted => RGBColor(148, 103, 189),
        Outcome::EnergyGrowth => RGBColor(255, 127, 14),
    }
}

/// One integrator's map: time step against E, coloured by outcome, with the
/// measured critical step and `2/ω_max` (both ∝ `1/√E`).
fn stability<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, map: &Map) -> Drawn {
    root.fill(&WHITE).map_err(err)?;
    let x = log_range(map.cells.iter().map(|c| c.young_pa));
    let y = log_range(map.cells.iter().map(|c| c.dt_s));
    let mut chart = ChartBuilder::on(root)
        .caption(
            format!(
                "{} {}: stability on cylinder {} (damping {} 1/s)",
                map.model.name(),
                map.integrator,
                map.mesh,
                map.damping_per_s
            ),
            ("sans-serif", 20),
        )
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d((x.0..x.1).log_scale(), (y.0..y.1).log_scale())
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_labels(6)
        .y_labels(6)
        .x_desc("Young's modulus E, Pa")
        .y_desc("time step, s")
        .x_label_formatter(&|v| format!("{v:.0e}"))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()
        .map_err(err)?;
    let curve = |dt0: f64| -> Vec<(f64, f64)> {
        (0..=40)
            .map(|k| {
                let e = x.0 * (x.1 / x.0).powf(f64::from(k) / 40.0);
                (e, dt0 * (map.reference_young_pa / e).sqrt())
            })
            .collect()
    };
    chart
        .draw_series(LineSeries::new(
            curve(map.critical_dt_s),
            BLACK.stroke_width(2),
        ))
        .map_err(err)?
        .label("measured critical step (linear)")
        .legend(|(x, y)| PathElement::new([(x, y), (x + 16, y)], BLACK.stroke_width(2)));
    let blue = RGBColor(31, 119, 180);
    chart
        .draw_series(DashedLineSeries::new(
            curve(map.two_over_omega_s),
            6,
            4,
            blue.stroke_width(2),
        ))
        .map_err(err)?
        .label("2/ω_max")
        .legend(move |(x, y)| PathElement::new([(x, y), (x + 16, y)], blue.stroke_width(2)));
    for outcome in [
        Outcome::Stable,
        Outcome::Diverged,
        Outcome::Inverted,
        Outcome::EnergyGrowth,
    ] {
        let colour = outcome_colour(outcome);
        chart
            .draw_series(
                map.cells
                    .iter()
                    .filter(|c| c.outcome == outcome)
                    .map(|c| Rectangle::new(square((c.young_pa, c.dt_s)), colour.filled())),
            )
            .map_err(err)?
            .label(format!("{outcome:?}").to_lowercase())
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 10, y + 5)], colour.filled()));
    }
    legend(&mut chart, SeriesLabelPosition::UpperRight)?;
    Ok(())
}

/// A small square around a log-log point (±8 %).
fn square((x, y): (f64, f64)) -> [(f64, f64); 2] {
    [(x / 1.08, y / 1.08), (x * 1.08, y * 1.08)]
}

/// Volume change against load, per model and protocol (Picinbono 2001
/// table 2).
fn volume_chart<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    results: &[SceneResult],
) -> Drawn {
    root.fill(&WHITE).map_err(err)?;
    let force = results
        .iter()
        .flat_map(|r| r.stages.iter().map(|s| s.force_n))
        .fold(0.0f64, f64::max);
    let volumes = results.iter().flat_map(|r| {
        r.stages.iter().flat_map(|s| {
            [&s.linear, &s.stvk, &s.stvk_incompressible].map(|e| 100.0 * e.volume_change)
        })
    });
    let (lo, hi) = volumes
        .filter(|v| v.is_finite())
        .fold((0.0f64, 0.0f64), |(lo, hi), v| (lo.min(v), hi.max(v)));
    let mut chart = ChartBuilder::on(root)
        .caption(
            "Picinbono 2001 table 2: volume change of the bent cylinder",
            ("sans-serif", 20),
        )
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..1.05 * force, (lo - 5.0)..(hi + 5.0))
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("total lateral force, N")
        .y_desc("(V − V₀)/V₀, %")
        .draw()
        .map_err(err)?;
    let models = [
        (
            "linear",
            Model::TensorMassLinear,
            (|s: &crate::experiment::volume_bend::Stage| &s.linear) as fn(_) -> _,
        ),
        ("StVK", Model::Stvk, |s| &s.stvk),
        ("StVK + penalty", Model::StvkPenalty, |s| {
            &s.stvk_incompressible
        }),
    ];
    for result in results {
        let (protocol, dashed) = match result.protocol {
            Protocol::PaperLoads => ("paper loads", false),
            Protocol::Tilt => ("tilts", true),
        };
        for (name, model, pick) in &models {
            let colour = model_colour(*model);
            let mut points = vec![(0.0, 0.0)];
            points.extend(
                result
                    .stages
                    .iter()
                    .map(|s| (s.force_n, 100.0 * pick(s).volume_change)),
            );
            let label = format!("{name}, {protocol}");
            if dashed {
                chart
                    .draw_series(DashedLineSeries::new(
                        points.clone(),
                        6,
                        4,
                        colour.stroke_width(2),
                    ))
                    .map_err(err)?
                    .label(label)
                    .legend(move |(x, y)| {
                        PathElement::new([(x, y), (x + 16, y)], colour.mix(0.6).stroke_width(1))
                    });
            } else {
                chart
                    .draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))
                    .map_err(err)?
                    .label(label)
                    .legend(move |(x, y)| {
                        PathElement::new([(x, y), (x + 16, y)], colour.stroke_width(2))
                    });
            }
            chart
                .draw_series(
                    points
                        .into_iter()
                        .map(|p| Circle::new(p, 4, colour.filled())),
                )
                .map_err(err)?;
        }
    }
    legend(&mut chart, SeriesLabelPosition::UpperLeft)?;
    Ok(())
}

/// Table bytes against `error`: a colour per encoding family, a marker per
/// mesh (circles, triangles, squares), each family's tables of one mesh
/// joined in order of bytes.
fn memory_chart<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    points: &[MemoryPoint],
    error: MemoryError,
) -> Drawn {
    root.fill(&WHITE).map_err(err)?;
    let xy = |p: &MemoryPoint| (p.bytes as f64, p.error(error).max(ERROR_FLOOR));
    let y_desc = error.axis();
    let axes = ["table bytes", y_desc.as_str()];
    let mut chart = log_frame(root, error.caption(), axes, points.iter().map(xy))?;
    let families = first_seen(points.iter().map(|p| p.family));
    let meshes = first_seen(points.iter().map(|p| p.mesh.as_str()));
    for (i, &family) in families.iter().enumerate() {
        let colour = FAMILY_COLOURS[i % FAMILY_COLOURS.len()];
        for (m, &mesh) in meshes.iter().enumerate() {
            let mut series: Vec<(f64, f64)> = points
                .iter()
                .filter(|p| p.family == family && p.mesh == mesh)
                .map(xy)
                .collect();
            series.sort_by(|a, b| a.0.total_cmp(&b.0));
            chart
                .draw_series(LineSeries::new(series.clone(), colour.stroke_width(2)))
                .map_err(err)?;
            chart
                .draw_series(
                    series
                        .into_iter()
                        .map(|p| EmptyElement::at(p) + mesh_marker::<DB>(m, colour.filled())),
                )
                .map_err(err)?;
        }
        chart
            .draw_series(core::iter::empty::<Circle<(f64, f64), i32>>())
            .map_err(err)?
            .label(family)
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 16, y + 5)], colour.filled()));
    }
    for (m, &mesh) in meshes.iter().enumerate() {
        chart
            .draw_series(core::iter::empty::<Circle<(f64, f64), i32>>())
            .map_err(err)?
            .label(mesh)
            .legend(move |(x, y)| {
                EmptyElement::at((x + 8, y)) + mesh_marker::<DB>(m, BLACK.filled())
            });
    }
    // Cheap and accurate, the corner no table reaches.
    legend(&mut chart, SeriesLabelPosition::LowerLeft)?;
    Ok(())
}

/// A colour per encoding family of a memory chart, in order of first
/// appearance (the model colours' palette).
const FAMILY_COLOURS: [RGBColor; 7] = [
    RGBColor(0, 0, 0),
    RGBColor(31, 119, 180),
    RGBColor(23, 190, 207),
    RGBColor(44, 160, 44),
    RGBColor(188, 189, 34),
    RGBColor(214, 39, 40),
    RGBColor(255, 127, 14),
];

/// The distinct `items`, in order of first appearance.
fn first_seen<'a>(items: impl Iterator<Item = &'a str>) -> Vec<&'a str> {
    let mut out: Vec<&str> = Vec::new();
    for item in items {
        if !out.contains(&item) {
            out.push(item);
        }
    }
    out
}

/// The marker of the `m`-th mesh of a memory chart, at the origin: a
/// circle, a triangle, then squares.
fn mesh_marker<DB: DrawingBackend>(
    m: usize,
    style: ShapeStyle,
) -> DynElement<'static, DB, (i32, i32)> {
    match m {
        0 => Circle::new((0, 0), 5, style).into_dyn(),
        1 => TriangleMarker::new((0, 0), 7, style).into_dyn(),
        _ => Rectangle::new([(-4, -4), (4, 4)], style).into_dyn(),
    }
}
