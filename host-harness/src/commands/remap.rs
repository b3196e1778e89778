//! `palpate remap fit`: the quasi-non-linear pre-computed model's remaps
//! (Cotin 1999 TVCG §3), fitted to a compression test's curves.

use std::path::PathBuf;

use clap::Subcommand;
use palpate::output::atomic;
use palpate::remap::curves::{self, to_csv};
use palpate::remap::fit::fit_curves;
use palpate::remap::sample::{Sample, linear_response, stvk_curves};
use palpate_kernel::precomputed::REMAP_DEGREE;

use super::args::MaterialArgs;
use super::stdout;

#[derive(Subcommand)]
pub enum RemapCommand {
    /// Fits the radial remap φ and the force remap ψ to compression curves
    /// (a CSV `force,axial,radial`, or St Venant-Kirchhoff curves of the
    /// sample when none is given) against the linear sample; prints the
    /// fit as JSON and writes it to `--out`.
    Fit {
        /// Measured curves (`force,axial,radial`: N, m, m; README "The
        /// quasi-non-linear pre-computed model"); default: generated.
        #[arg(long)]
        curves: Option<PathBuf>,
        /// The sample's (and the tissue's) material.
        #[command(flatten)]
        material: MaterialArgs,
        /// Sample height, m.
        #[arg(long, default_value_t = 0.02)]
        sample_height_m: f64,
        /// Sample radius, m.
        #[arg(long, default_value_t = 0.004)]
        sample_radius_m: f64,
        /// Generated curves: largest compression, fraction of the height.
        #[arg(long, default_value_t = 0.25)]
        max_strain: f64,
        /// Generated curves: compression steps.
        #[arg(long, default_value_t = 8)]
        steps: usize,
        /// Polynomial degree, 1..=REMAP_DEGREE.
        #[arg(long, default_value_t = 3)]
        degree: usize,
        /// The fit, JSON (written atomically).
        #[arg(long)]
        out: PathBuf,
        /// Also write the curves fitted (CSV, the `--curves` format).
        #[arg(long)]
        curves_out: Option<PathBuf>,
    },
}

/// Runs a `remap` command.
pub fn run(command: RemapCommand) -> anyhow::Result<()> {
    match command {
        RemapCommand::Fit {
            curves,
            material,
            sample_height_m,
            sample_radius_m,
            max_strain,
            steps,
            degree,
            out,
            curves_out,
        } => {
            anyhow::ensure!(
                (1..=REMAP_DEGREE).contains(&degree),
                "--degree {degree}: must be in 1..={REMAP_DEGREE}"
            );
            let inputs: Vec<(&str, &std::path::Path)> =
                curves.iter().map(|c| ("--curves", c.as_path())).collect();
            atomic::refuse_input(("--out", out.as_path()), &inputs)?;
            if let Some(c) = &curves_out {
                atomic::refuse_input(("--curves-out", c.as_path()), &inputs)?;
            }
            let sample = Sample::new(sample_height_m, sample_radius_m, material.material()?)?;
            let (points, source) = match &curves {
                Some(path) => (curves::read(path)?, "measured"),
                None => (
                    stvk_curves(&sample, max_strain, steps)?,
                    "st-venant-kirchhoff-sample",
                ),
            };
            let linear = linear_response(&sample)?;
            let fitted = fit_curves(&points, &linear, degree)?;
            fitted.kernel::<f32>()?;
            let json = serde_json::json!({
                "source": source,
                "degree": degree,
                "sample": { "height_m": sample_height_m, "radius_m": sample_radius_m },
                "fit": fitted,
            });
            let text = serde_json::to_string_pretty(&json)?;
            atomic::write_file(&out, text.as_bytes())?;
            if let Some(path) = &curves_out {
                atomic::write_file(path, to_csv(&points).as_bytes())?;
            }
            stdout::println(&text)?;
            Ok(())
        }
    }
}
