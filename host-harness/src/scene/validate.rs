//! The checks of a [`Scene`]: [`Scene::validate`] (every invariant, without the mesh), one
//! named stage per part of the scene, and [`Scene::check_on_mesh`] (what needs the mesh).

use super::error::SceneError;
use super::materials::check_regions;
use super::spec::{
    CuttingSpec, DynamicSpec, MAX_CAPACITY_TETS, MAX_SUBSTEPS, ModelSpec, Scene, TearingSpec,
    substeps,
};
use super::tool::{MAX_TOOL_POINTS, MAX_TOOL_RADIUS_FRACTION, check_tool, length};
use crate::fem::material::{MaterialError, POISSON_RANGE};
use crate::limits::MAX_HAPTIC_HZ;
use crate::mesh::TetMesh;
use crate::output::number::shown;

impl Scene {
    /// The checks of the scene that need its loaded `mesh`: `[tool] radius_m` at most
    /// [`MAX_TOOL_RADIUS_FRACTION`] of the mesh's largest bounding-box extent.
    pub fn check_on_mesh(&self, mesh: &TetMesh) -> Result<(), SceneError> {
        let (lo, hi) = mesh.positions.iter().fold(
            ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
            |(lo, hi), p| {
                (
                    [0, 1, 2].map(|i| lo[i].min(p[i])),
                    [0, 1, 2].map(|i| hi[i].max(p[i])),
                )
            },
        );
        let extent = (0..3).map(|i| hi[i] - lo[i]).fold(0.0, f64::max);
        let most = MAX_TOOL_RADIUS_FRACTION * extent;
        if self.tool.radius_m > most {
            return Err(SceneError::Invalid {
                file: self.source.clone(),
                key: format!("[tool] radius_m = {}", self.tool.radius_m),
                msg: format!(
                    "above {MAX_TOOL_RADIUS_FRACTION} of the mesh's largest extent ({extent} m): \
                     at most {most} m (MAX_TOOL_RADIUS_FRACTION); a tool wider than the body \
                     touches all of it"
                ),
            });
        }
        Ok(())
    }

    /// Check every invariant of [`Scene`]; the error names [`Scene::source`] and the key. The
    /// stages run in this order, the first error returned: the mesh source, the fixed vertices,
    /// the material, the tool, the regions, the tool kinds, cutting and tearing, the rates, the
    /// safety limits, the loop's f32 range, the dynamic model.
    pub fn validate(&self) -> Result<(), SceneError> {
        let in_file = |(key, msg): (String, String)| SceneError::Invalid {
            file: self.source.clone(),
            key,
            msg,
        };
        self.mesh.check().map_err(in_file)?;
        self.check_fix().map_err(in_file)?;
        self.check_material().map_err(in_file)?;
        self.check_tool_size().map_err(in_file)?;
        let m = &self.material;
        check_regions(&self.regions, m.elastic.young_pa, m.density_kg_m3).map_err(in_file)?;
        check_tool(&self.tool).map_err(in_file)?;
        check_removal(&self.cutting, self.tearing.as_ref(), &self.model).map_err(in_file)?;
        self.check_rates().map_err(in_file)?;
        self.check_safety().map_err(in_file)?;
        self.check_f32_range().map_err(in_file)?;
        if let ModelSpec::Dynamic(d) = &self.model {
            check_dynamic(d, self.physics_period_s()).map_err(in_file)?;
        }
        Ok(())
    }

    /// A pre-computed scene has at least one `fix` predicate; errors are `(key, message)`.
    fn check_fix(&self) -> Result<(), (String, String)> {
        if self.fix.is_empty() && self.model == ModelSpec::Precomputed {
            return invalid(
                "fix = []".into(),
                "the pre-computed model needs at least one fixed-vertex predicate (a free body has no compliance)",
            );
        }
        Ok(())
    }

    /// `[material]`: `E` and `ν` in [`crate::fem::material::Material::new`]'s ranges, the
    /// density finite and > 0; errors are `(key, message)`.
    fn check_material(&self) -> Result<(), (String, String)> {
        let m = &self.material;
        if let Err(err) = m.elastic.check() {
            return match err {
                MaterialError::YoungModulus(e) => invalid(
                    format!("[material] young_pa = {}", shown(e)),
                    "must be finite and > 0 Pa",
                ),
                MaterialError::PoissonRatio(nu) => invalid(
                    format!("[material] poisson = {}", shown(nu)),
                    &format!("must satisfy {POISSON_RANGE}"),
                ),
            };
        }
        if !positive(m.density_kg_m3) {
            return invalid(
                format!("[material] density_kg_m3 = {}", shown(m.density_kg_m3)),
                "must be finite and > 0 kg/m3",
            );
        }
        Ok(())
    }

    /// `[tool] points` in `1..=MAX_TOOL_POINTS`, `radius_m` finite and > 0; errors are
    /// `(key, message)`.
    fn check_tool_size(&self) -> Result<(), (String, String)> {
        if !(1..=MAX_TOOL_POINTS).contains(&self.tool.points) {
            return invalid(
                format!("[tool] points = {}", self.tool.points),
                &format!("must be in 1..={MAX_TOOL_POINTS} (the kernel's contact capacity)"),
            );
        }
        if !positive(self.tool.radius_m) {
            return invalid(
                format!("[tool] radius_m = {}", shown(self.tool.radius_m)),
                "must be finite and > 0 m",
            );
        }
        Ok(())
    }

    /// `[rates]`: `haptic_hz` finite, > 0 and at most [`MAX_HAPTIC_HZ`], `physics_every ≥ 1`,
    /// the tick and physics periods finite; errors are `(key, message)`.
    fn check_rates(&self) -> Result<(), (String, String)> {
        if !positive(self.rates.haptic_hz) {
            return invalid(
                format!("[rates] haptic_hz = {}", shown(self.rates.haptic_hz)),
                "must be finite and > 0 Hz",
            );
        }
        if self.rates.haptic_hz > MAX_HAPTIC_HZ {
            return invalid(
                format!("[rates] haptic_hz = {}", shown(self.rates.haptic_hz)),
                &format!(
                    "above {MAX_HAPTIC_HZ} Hz (MAX_HAPTIC_HZ): haptic devices servo at 1 to 10 kHz"
                ),
            );
        }
        if self.rates.physics_every == 0 {
            return invalid(
                "[rates] physics_every = 0".into(),
                "must be >= 1 (a physics update every this many ticks)",
            );
        }
        if !(positive(self.tick_s()) && positive(self.physics_period_s())) {
            return invalid(
                format!("[rates] haptic_hz = {}", shown(self.rates.haptic_hz)),
                "too small: 1/haptic_hz and physics_every/haptic_hz must be finite seconds",
            );
        }
        Ok(())
    }

    /// `[safety]`: both limits finite and > 0; errors are `(key, message)`.
    fn check_safety(&self) -> Result<(), (String, String)> {
        if !positive(self.safety.max_force_n) {
            return invalid(
                format!("[safety] max_force_n = {}", shown(self.safety.max_force_n)),
                "must be finite and > 0 N",
            );
        }
        if !positive(self.safety.max_slew_n_per_s) {
            return invalid(
                format!(
                    "[safety] max_slew_n_per_s = {}",
                    shown(self.safety.max_slew_n_per_s)
                ),
                "must be finite and > 0 N/s",
            );
        }
        Ok(())
    }

    /// The values the loop takes in f32 (`session::setup::loop_config`) within its range: a value
    /// beyond it would reach the kernel as infinity or zero. Errors are `(key, message)`.
    fn check_f32_range(&self) -> Result<(), (String, String)> {
        let in_f32 = |x: f64| {
            let y = x as f32;
            y.is_finite() && y > 0.0
        };
        let f32_range = format!("between {:e} and {:e}", f32::MIN_POSITIVE, f32::MAX);
        for (key, value, unit) in [
            ("[safety] max_force_n", self.safety.max_force_n, "N"),
            (
                "[safety] max_slew_n_per_s",
                self.safety.max_slew_n_per_s,
                "N/s",
            ),
            ("[tool] radius_m", self.tool.radius_m, "m"),
            ("[tool] grip_opening_m", self.tool.grip_opening_m, "m"),
        ] {
            if !in_f32(value) {
                return invalid(
                    format!("{key} = {value:e}"),
                    &format!("out of range of the loop's f32: must lie {f32_range} {unit}"),
                );
            }
        }
        if !in_f32(self.tick_s()) {
            return invalid(
                format!("[rates] haptic_hz = {:e}", self.rates.haptic_hz),
                &format!("out of range of the loop's f32: 1/haptic_hz must lie {f32_range} s"),
            );
        }
        if !in_f32(length(self.tool.blade_m)) {
            return invalid(
                format!("[tool] blade_m = {:?}", self.tool.blade_m),
                &format!("out of range of the loop's f32: its length must lie {f32_range} m"),
            );
        }
        Ok(())
    }
}

/// A stage's error: `(key, message)`.
fn invalid(key: String, msg: &str) -> Result<(), (String, String)> {
    Err((key, msg.to_owned()))
}

/// Finite and > 0.
fn positive(x: f64) -> bool {
    x.is_finite() && x > 0.0
}

/// The ranges of `[cutting]` and `[tearing]`; errors are `(key, message)`.
fn check_removal(
    cutting: &CuttingSpec,
    tearing: Option<&TearingSpec>,
    model: &ModelSpec,
) -> Result<(), (String, String)> {
    let capacity = |table: &str, capacity: u32| {
        if (1..=MAX_CAPACITY_TETS).contains(&capacity) {
            Ok(())
        } else {
            Err((
                format!("[{table}] capacity_tets = {capacity}"),
                format!(
                    "must be in 1..={MAX_CAPACITY_TETS} (MAX_CAPACITY_TETS: tets one physics update removes at most)"
                ),
            ))
        }
    };
    capacity("cutting", cutting.capacity_tets)?;
    let force = cutting.force_n;
    if !(force.is_finite() && force > 0.0 && force <= f64::from(f32::MAX)) {
        return Err((
            format!("[cutting] force_n = {force}"),
            "must be finite, > 0 N and fit f32".into(),
        ));
    }
    let Some(tearing) = tearing else {
        return Ok(());
    };
    if *model == ModelSpec::Precomputed {
        return Err((
            "[tearing]".into(),
            "applies to kind = \"dynamic\" only (this scene is \"precomputed\", which cannot tear)"
                .into(),
        ));
    }
    let criteria = [
        ("volume_change", tearing.volume_change),
        ("mean_elongation", tearing.mean_elongation),
        ("max_elongation", tearing.max_elongation),
    ];
    if criteria.iter().all(|(_, value)| value.is_none()) {
        return Err((
            "[tearing]".into(),
            "no criterion: give at least one of volume_change, mean_elongation and max_elongation (or remove the table: no tearing)".into(),
        ));
    }
    for (key, value) in criteria {
        if let Some(x) = value
            && !(x.is_finite() && x > 0.0)
        {
            return Err((
                format!("[tearing] {key} = {x}"),
                "must be finite and > 0".into(),
            ));
        }
    }
    capacity("tearing", tearing.capacity_tets)
}

/// The ranges of a [`DynamicSpec`]; errors are `(key, message)`.
fn check_dynamic(d: &DynamicSpec, physics_period_s: f64) -> Result<(), (String, String)> {
    if let Some(gamma) = d.incompressibility_n
        && !(gamma.is_finite() && gamma >= 0.0)
    {
        return Err((
            format!("[model] incompressibility_n = {gamma}"),
            "must be finite and >= 0 N".into(),
        ));
    }
    if !(d.damping_per_s.is_finite() && d.damping_per_s >= 0.0) {
        return Err((
            format!("[model] damping_per_s = {}", shown(d.damping_per_s)),
            "must be finite and >= 0 1/s".into(),
        ));
    }
    if !(d.dt_s.is_finite() && d.dt_s > 0.0) {
        return Err((
            format!("[model] dt_s = {}", shown(d.dt_s)),
            "must be finite and > 0 s".into(),
        ));
    }
    if substeps(physics_period_s, d.dt_s).is_none() {
        return Err((
            format!("[model] dt_s = {}", shown(d.dt_s)),
            format!(
                "the physics period ({physics_period_s} s = physics_every / haptic_hz) must be a whole number of steps, 1 to {MAX_SUBSTEPS}"
            ),
        ));
    }
    Ok(())
}
