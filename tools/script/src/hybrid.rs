//! The scripted hybrid run (RR-3510 §6.2), shared by `palpate scene
//! replay-hybrid` and the firmware's hybrid binary, so that both run the
//! same kernel calls and print the same bytes.
//!
//! # Sequence
//! The crate's step syntax, one line per physics step (mesh vertex numbers).
//! A vertex contact on a vertex of the tensor-mass region imposes that
//! displacement on it (`TensorMassModel::impose`; it stays imposed for the
//! rest of the run, a later line may change it). Every other contact is a
//! tool contact on the pre-computed region, solved against the background
//! the connection nodes and the load give it
//! (`HybridModel::contact_forces`); its force is passed to the connection
//! nodes (`pass_contact_forces`) before the step.
//!
//! # Each step
//! `update_background` (the touchable rows), the contact solve, the passed
//! forces, then [`STEPS_PER_LINE`] steps of [`INTEGRATOR`] with [`DT_S`]
//! under [`params`], then the displacement of every mesh vertex
//! (`HybridModel::displacements`).
//!
//! # Output (one line per step, f32 bit patterns in hex)
//! - `step <i> device <fx> <fy> <fz> contacts <g0x> <g0y> <g0z> ... umax <u>
//!   ke <e>`: device and contact forces on the pre-computed region (N), the
//!   largest absolute displacement component of any vertex (m), the
//!   tensor-mass region's kinetic energy after the step (J);
//! - `step <i> error <message>` when the kernel refuses the imposed
//!   displacement (no step), the contact set (the step runs without
//!   pre-computed contacts) or the step (the run ends there).

use core::fmt::Write;

use palpate_kernel::MAX_CONTACTS;
use palpate_kernel::hybrid::HybridModel;
use palpate_kernel::precomputed::{Constraint, ContactPoint};
use palpate_kernel::tensor_mass::{DynamicParams, ElasticLaw, InputError, Integrator, StvkForm};

use crate::parse::{StepContacts, steps};
use crate::replay::{ReplayError, check_inputs, hex, largest, write_forces};

/// The tensor-mass region's integrator (the scene's `[model] integrator`).
pub const INTEGRATOR: Integrator = Integrator::SymplecticEuler;

/// The physics step, s (the scene's `[model] dt_s`; below the stable step
/// that `palpate scene plan` prints for the firmware box).
pub const DT_S: f32 = 5e-4;

/// Physics steps per sequence line.
pub const STEPS_PER_LINE: u32 = 4;

/// The tensor-mass region's laws the replay can run, by the name `palpate
/// scene replay-hybrid --law` and `tools/firmware-check.sh --hybrid --law`
/// take (the scene's `[model] law` names): linear (the scene's), St
/// Venant-Kirchhoff tet by tet, co-rotational, neo-Hookean. None needs a
/// buffer beyond the linear law's (no split St Venant-Kirchhoff terms).
pub const LAWS: [(&str, ElasticLaw); 4] = [
    ("linear", ElasticLaw::Linear),
    ("stvk", ElasticLaw::StVenantKirchhoff(StvkForm::PerTet)),
    ("corotational", ElasticLaw::Corotational),
    ("neo-hookean", ElasticLaw::NeoHookean),
];

/// The law of [`LAWS`] named `name`, `None` for another name.
pub fn law_named(name: &str) -> Option<ElasticLaw> {
    LAWS.iter().find(|(n, _)| *n == name).map(|&(_, law)| law)
}

/// The tensor-mass region's parameters: elastic `law` (the scene's is
/// linear), mass-proportional damping 20 /s (the scene's `[model]
/// damping_per_s`), divergence bound 0.01 m (a third of the box).
pub fn params(law: ElasticLaw) -> DynamicParams<f32> {
    DynamicParams::linear(20.0, 0.01).with_law(law)
}

/// Runs every line of `sequence` on `model` (f32, built with [`params`] of a
/// law of [`LAWS`]) and
/// writes one line per step to `out`; `displacements` holds one entry per
/// mesh vertex. The whole sequence is parsed before anything is written.
pub fn replay<W: Write>(
    model: &mut HybridModel<'_, '_, f32>,
    sequence: &str,
    displacements: &mut [[f32; 3]],
    out: &mut W,
) -> Result<(), ReplayError> {
    check_inputs(model.interface().vertex_count(), sequence, displacements)?;
    let touchable = model.region().precomputed().table().touchable_count();
    for (index, (_, step)) in steps::<f32>(sequence).enumerate() {
        let Ok(contacts) = step else { continue };
        write!(out, "step {index}")?;
        let tool = match impose(model, &contacts) {
            Ok(tool) => tool,
            Err(error) => {
                writeln!(out, " error {error}")?;
                continue;
            }
        };
        // A faulted region leaves the background as it was; its step says so.
        let _ = model.update_background(touchable);
        let solution = model.contact_forces::<MAX_CONTACTS>(&tool);
        model.pass_contact_forces(solution.as_ref().ok());
        let mut kinetic_energy_j = 0.0f32;
        for _ in 0..STEPS_PER_LINE {
            match model.step(INTEGRATOR, DT_S) {
                Ok(report) => kinetic_energy_j = report.kinetic_energy_j,
                Err(error) => {
                    writeln!(out, " error {error}")?;
                    return Ok(());
                }
            }
        }
        let solution = match solution {
            Ok(solution) => solution,
            Err(error) => {
                writeln!(out, " error {error}")?;
                continue;
            }
        };
        write_forces(out, &solution)?;
        let umax = match model.displacements(Some(&solution), displacements) {
            Ok(()) => largest(displacements),
            Err(_) => f32::NAN,
        };
        writeln!(out, " umax {} ke {}", hex(umax), hex(kinetic_energy_j))?;
    }
    Ok(())
}

/// Imposes the vertex contacts of `contacts` that lie on the tensor-mass
/// region and returns the others (the tool contacts on the pre-computed
/// region).
fn impose(
    model: &mut HybridModel<'_, '_, f32>,
    contacts: &[Constraint<f32>],
) -> Result<StepContacts<f32>, InputError> {
    let mut tool = StepContacts::new();
    for contact in contacts {
        let dynamic = match contact.point {
            ContactPoint::Vertex(v) => model.interface().dynamic_vertex(v),
            ContactPoint::Triangle { .. } => None,
        };
        match dynamic {
            Some(d) => model.dynamic_mut().impose(d, contact.displacement_m)?,
            // At most as many as `contacts` holds (`MAX_CONTACTS`).
            None => {
                let _ = tool.push(*contact);
            }
        }
    }
    Ok(tool)
}
