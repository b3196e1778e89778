//! Argument groups several commands share, each flattened into a command
//! with `#[command(flatten)]`: the material (`--young`, `--poisson`; with `--density` where a
//! scene may stand in for them), the fixed-vertex predicates (`--fix`) and the JSON-only output switch
//! (`--json`); and the values of `--form`, which two commands take.

use anyhow::bail;
use palpate::fem::material::Material;
use palpate::fix::FixPredicate;
use palpate_kernel::tensor_mass::StvkForm;

/// `--young` and `--poisson`: an isotropic linear elastic material. Negative
/// numbers parse (`--young -3000`), so that [`Self::material`] refuses them
/// with the physics reason instead of clap's usage error.
#[derive(clap::Args)]
pub struct MaterialArgs {
    /// Young's modulus, Pa.
    #[arg(long, allow_negative_numbers = true)]
    pub young: f64,
    /// Poisson ratio, in [0, 0.4999].
    #[arg(long, allow_negative_numbers = true)]
    pub poisson: f64,
}

impl MaterialArgs {
    /// The validated material.
    pub fn material(&self) -> anyhow::Result<Material> {
        Ok(Material::new(self.young, self.poisson)?)
    }
}

/// `--young`, `--poisson` and `--density` of a command that takes a mesh or, in its place, a
/// scene (`--scene`, which must be an argument of the same command): required unless `--scene`
/// is given. Negative numbers parse, as for [`MaterialArgs`].
#[derive(clap::Args)]
pub struct MassMaterialArgs {
    /// Young's modulus, Pa.
    #[arg(long, allow_negative_numbers = true, required_unless_present = "scene")]
    pub young: Option<f64>,
    /// Poisson ratio, in [0, 0.4999].
    #[arg(long, allow_negative_numbers = true, required_unless_present = "scene")]
    pub poisson: Option<f64>,
    /// Mass density, kg/m3.
    #[arg(long, required_unless_present = "scene")]
    pub density: Option<f64>,
}

impl MassMaterialArgs {
    /// The validated material and the density (kg/m³) when all three are given, `None` when
    /// none is (`--scene` in their place).
    pub fn given(&self) -> Option<anyhow::Result<(Material, f64)>> {
        let (Some(young), Some(poisson), Some(density)) = (self.young, self.poisson, self.density)
        else {
            return None;
        };
        Some(
            MaterialArgs { young, poisson }
                .material()
                .map(|m| (m, density)),
        )
    }
}

/// `--fix` (repeatable): the fixed-vertex predicates, required. A model
/// that admits a free body makes them optional with
/// `#[command(mut_arg("fix", optional_fix))]` (an override that keeps the
/// required arguments of the usage line in their order).
#[derive(clap::Args)]
pub struct FixArgs {
    /// Fixed vertices: x|y|z then <, <=, > or >= then a number in mesh units (repeatable).
    #[arg(long = "fix", required = true, value_parser = parse_fix, allow_hyphen_values = true)]
    pub fix: Vec<FixPredicate>,
}

/// `--fix` made optional: none fixes nothing (a free body).
pub fn optional_fix(fix: clap::Arg) -> clap::Arg {
    fix.required(false).help(
        "Fixed vertices: x|y|z then <, <=, > or >= then a number (repeatable; none = free body)",
    )
}

/// Parses one `--fix`-syntax predicate (also `chart --load-on`).
pub fn parse_fix(s: &str) -> Result<FixPredicate, String> {
    s.parse()
}

/// `--threads` of a command that steps a tensor-mass model.
#[derive(clap::Args, Clone, Copy)]
pub struct ThreadsArgs {
    /// Threads of the per-tet force pass (St Venant-Kirchhoff per tet,
    /// co-rotational, neo-Hookean; 1 to 8): the results are the same bits for
    /// any count, 1 runs the pass in one piece. Default 1 (threads started
    /// per pass cost more than they save; docs/bench.md).
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=8))]
    pub threads: Option<u8>,
}

impl ThreadsArgs {
    /// The thread count: `--threads`, or [`palpate::threads::default_threads`].
    pub fn count(&self) -> usize {
        self.threads
            .map_or_else(palpate::threads::default_threads, usize::from)
    }
}

/// `--json` of a command whose only output format is one JSON object.
#[derive(clap::Args)]
pub struct JsonArgs {
    /// Print one JSON object (the only output format).
    #[arg(long)]
    pub json: bool,
}

impl JsonArgs {
    /// Refuses to run `command` without `--json`: the format is named on the
    /// command line, so another can be added later.
    pub fn require(&self, command: &str) -> anyhow::Result<()> {
        if !self.json {
            bail!("{command} prints JSON only: pass --json");
        }
        Ok(())
    }
}

/// `--form`: the two St Venant-Kirchhoff implementations.
#[derive(Clone, Copy, clap::ValueEnum)]
pub enum FormArg {
    /// Per tet from the deformation gradient.
    PerTet,
    /// Picinbono's split terms on vertices, edges, triangles and tets.
    Tensors,
}

impl From<FormArg> for StvkForm {
    fn from(form: FormArg) -> Self {
        match form {
            FormArg::PerTet => StvkForm::PerTet,
            FormArg::Tensors => StvkForm::Tensors,
        }
    }
}

/// A real argument: parsed, and refused by clap in one line (`error:
/// invalid value '-1' for '--dt <DT>': must be finite and > 0`) when it is
/// not finite or `check` refuses it. Declare the argument with
/// `allow_negative_numbers = true`, so that a negative value reaches the
/// parser instead of clap's usage error.
fn real(s: &str, check: impl Fn(f64) -> bool, range: &str) -> Result<f64, String> {
    let x: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("not a number; expected {range}"))?;
    if x.is_finite() && check(x) {
        Ok(x)
    } else {
        Err(format!("must be {range}"))
    }
}

/// Value parser of a real `> 0` (`--dt`).
pub fn positive(s: &str) -> Result<f64, String> {
    real(s, |x| x > 0.0, "finite and > 0")
}

/// Value parser of a real `>= 0` (`--damping`).
pub fn non_negative(s: &str) -> Result<f64, String> {
    real(s, |x| x >= 0.0, "finite and >= 0")
}

/// Value parser of a fraction in `[0, 1)` (`--drop-below`).
pub fn fraction(s: &str) -> Result<f64, String> {
    real(s, |x| (0.0..1.0).contains(&x), "a fraction in [0, 1)")
}

/// Value parser of a vector `x,y,z` of finite reals (`--gravity`).
pub fn finite_vector(s: &str) -> Result<[f64; 3], String> {
    let v: [f64; 3] = palpate_script::parse_vector(s).map_err(|e| e.to_string())?;
    if v.iter().all(|c| c.is_finite()) {
        Ok(v)
    } else {
        Err("each of the three components must be a finite number".into())
    }
}
