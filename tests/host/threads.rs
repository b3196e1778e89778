//! The tensor-mass step with its per-tet force pass split over threads
//! (`host-harness/src/threads.rs`, `kernel/src/tensor_mass/split.rs`): for
//! every law, with and without the penalty, for every integrator, the
//! state after a few steps on 1, 2, 3 and 4 threads is the state of the
//! pass in one piece (a model without split buffers), and so is the state
//! when the parts run in reverse order on one thread.
//!
//! Tolerance: none, bit for bit. Split, each vertex gathers its tets'
//! corner forces in tet order, the order in which the pass in one piece
//! scatters them, from the same per-tet values; the other passes (linear,
//! split terms, penalty, the integrator's update) run in one piece either
//! way. Independent truth: the unsplit pass, which the firmware, the
//! replays and the reference tests check. A gather that missed a tet, read
//! a removed one or summed in another order would differ in the last bits
//! at least.

use palpate::dispatch::HostDispatch;
use palpate::mesh::{MeshReport, TetMesh};
use palpate::table::build::build;
use palpate::table::file::Precision;
use palpate::table::load::TableFile;
use palpate::threads::Threaded;
use palpate_kernel::Real;
use palpate_kernel::math::{Dispatch, MAX_PARTS, Portable};
use palpate_kernel::tensor_mass::{ElasticLaw, Integrator};

use super::dispatch::{bits, meshes, options, stepped};

/// A serial dispatch that cuts the split passes into `0` parts and runs
/// them last first: the result must not depend on the order of the parts.
#[derive(Clone, Copy)]
struct Reversed(usize);

impl Dispatch for Reversed {
    fn run<R>(self, pass: impl FnOnce() -> R) -> R {
        pass()
    }

    fn parts(self) -> usize {
        self.0
    }

    fn each<I: Send>(self, items: [Option<I>; MAX_PARTS], job: impl Fn(I) + Sync) {
        for item in items.into_iter().rev().flatten() {
            job(item);
        }
    }
}

/// The cases of `precision` on `meshes`: every law and form, with and
/// without the penalty, semi-implicit Euler and RK4 (four force passes a
/// step), each on 1–4 threads and in 3 reversed parts.
fn check<T: Real>(precision: Precision, meshes: &[TetMesh]) -> usize {
    let options = options(precision);
    let detected = HostDispatch::detect();
    let mut compared = 0;
    for mesh in meshes {
        let file =
            TableFile::from_bytes(&build(mesh, &MeshReport::default(), &options).unwrap().bytes);
        for law in ElasticLaw::ALL {
            for penalty in [None, Some(0.05)] {
                for integrator in [Integrator::SymplecticEuler, Integrator::Rk4] {
                    let whole = stepped::<T>(mesh, &file, law, penalty, integrator, Portable);
                    assert!(
                        whole.iter().flatten().any(|x| *x != T::zero()),
                        "the state moved"
                    );
                    let mut check = |name: String, split: Vec<[T; 3]>| {
                        let same = whole
                            .iter()
                            .flatten()
                            .zip(split.iter().flatten())
                            .all(|(a, b)| bits(*a) == bits(*b));
                        assert!(
                            same && whole.len() == split.len(),
                            "{law:?} penalty {penalty:?} {integrator:?} {precision:?} {name}: differs from the pass in one piece"
                        );
                        compared += 1;
                    };
                    for threads in 1..=4 {
                        let dispatch = Threaded::new(detected, threads);
                        let split = stepped::<T>(mesh, &file, law, penalty, integrator, dispatch);
                        check(format!("{threads} threads ({})", detected.name()), split);
                    }
                    let reversed = stepped::<T>(mesh, &file, law, penalty, integrator, Reversed(3));
                    check("3 parts in reverse".to_owned(), reversed);
                }
            }
        }
    }
    compared
}

#[test]
fn split_steps_equal_the_pass_in_one_piece_bit_for_bit() {
    // Kept to about 3 s in debug: f64 on both meshes, f32 on the box.
    let [cylinder, block] = meshes();
    let both = [cylinder, block.clone()];
    // 5 laws and forms × 2 penalties × 2 integrators × 5 (1–4 threads,
    // reversed parts) per mesh.
    assert_eq!(check::<f64>(Precision::F64, &both), 5 * 2 * 2 * 5 * 2);
    assert_eq!(check::<f32>(Precision::F32, &[block]), 5 * 2 * 2 * 5);
}
