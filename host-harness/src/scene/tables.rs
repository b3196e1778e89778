//! A scene's `[tables]` table: how the pre-computed model's compliance table
//! is stored, the scene-file form of `tables build --compress`.
//!
//! ```toml
//! [tables]
//! compress = "hmatrix"   # "f16", "q16", "hmatrix" or "hmatrix-q16"; absent: the
//!                        # f32 table
//! tolerance = 1e-4       # hmatrix and hmatrix-q16 only: the far blocks' relative
//!                        # truncation tolerance, in (0, 1); default the build's
//! drop_below = 0.01      # f16 and q16 only: the interior blocks dropped below this
//!                        # fraction of their column's largest, in [0, 1); default 0
//! ```
//!
//! A pre-computed scene's compliance table takes every code; a hybrid
//! scene's `"hmatrix"` only (`"hmatrix-q16"` is refused there as `"f16"` and
//! `"q16"` are), which stores its interface's condensed
//! stiffness hierarchically (`crate::hybrid::hmatrix`, `tolerance` its far
//! blocks'); a tensor-mass scene none (`crate::session::model` refuses
//! them).

use serde::Deserialize;

use crate::hybrid::hmatrix::InterfaceCompression;
use crate::table::hmatrix::DEFAULT_TOLERANCE;

/// How the compliance is stored, `compress = …`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TableCode {
    /// IEEE 754 binary16 codes times a per-column scale.
    F16,
    /// 16-bit fixed point times a per-column scale.
    Q16,
    /// A hierarchical matrix: near blocks and low-rank far blocks.
    Hmatrix,
    /// The hierarchical matrix with its numbers as 16-bit fixed point
    /// (`tables build --compress hmatrix-q16`); a pre-computed scene's only.
    HmatrixQ16,
}

impl TableCode {
    /// The code as a scene file writes it (`compress = "…"`).
    pub fn name(self) -> &'static str {
        match self {
            TableCode::F16 => "f16",
            TableCode::Q16 => "q16",
            TableCode::Hmatrix => "hmatrix",
            TableCode::HmatrixQ16 => "hmatrix-q16",
        }
    }
}

/// The `[tables]` table, validated (`TablesSpec::new`): `compress`
/// absent means the f32 table, and then neither option is given.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TablesSpec {
    /// The code, `None` for the f32 table.
    pub compress: Option<TableCode>,
    /// `hmatrix` and `hmatrix-q16` only: the far blocks' relative tolerance, in `(0, 1)`;
    /// `None`: the build's default.
    pub tolerance: Option<f64>,
    /// `f16`/`q16` only: the drop threshold, in `[0, 1)`; `None`: 0.
    pub drop_below: Option<f64>,
}

/// `[tables]` as written.
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct TablesFile {
    compress: Option<TableCode>,
    tolerance: Option<f64>,
    drop_below: Option<f64>,
}

impl TablesSpec {
    /// Checks `[tables]`: each option only with the code it applies to, in
    /// its range. Errors are `(key, message)`.
    pub(super) fn new(raw: &TablesFile) -> Result<Self, (String, String)> {
        let spec = Self {
            compress: raw.compress,
            tolerance: raw.tolerance,
            drop_below: raw.drop_below,
        };
        let hmatrix = matches!(
            spec.compress,
            Some(TableCode::Hmatrix | TableCode::HmatrixQ16)
        );
        let coded = matches!(spec.compress, Some(TableCode::F16 | TableCode::Q16));
        let fail = |key: &str, msg: &str| Err((format!("[tables] {key}"), msg.to_owned()));
        if let Some(tolerance) = spec.tolerance {
            if !hmatrix {
                return fail(
                    "tolerance",
                    "applies to compress = \"hmatrix\" or \"hmatrix-q16\" only",
                );
            }
            if !(tolerance.is_finite() && tolerance > 0.0 && tolerance < 1.0) {
                return fail("tolerance", "must be a relative tolerance in (0, 1)");
            }
        }
        if let Some(drop_below) = spec.drop_below {
            if !coded {
                return fail(
                    "drop_below",
                    "applies to compress = \"f16\" or \"q16\" only",
                );
            }
            if !(drop_below.is_finite() && (0.0..1.0).contains(&drop_below)) {
                return fail("drop_below", "must be a fraction in [0, 1)");
            }
        }
        Ok(spec)
    }
}

impl TablesSpec {
    /// How a hybrid's interface is compressed: its condensed stiffness hierarchical for
    /// `compress = "hmatrix"` (this `tolerance`, the default leaves), else `None` (dense; a
    /// hybrid's build refuses the other codes, `crate::session::model::hybrid_tables`).
    pub fn interface_compression(&self) -> Option<InterfaceCompression> {
        (self.compress == Some(TableCode::Hmatrix)).then(|| InterfaceCompression {
            tolerance: self.tolerance.unwrap_or(DEFAULT_TOLERANCE),
            ..InterfaceCompression::default()
        })
    }
}
