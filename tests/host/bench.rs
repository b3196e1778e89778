//! `palpate::bench` as a library (`host-harness/src/bench/`): the call
//! `palpate chart` times a configuration with. Shapes only, no timed
//! assertion: a positive median inside its spread, the requested samples,
//! no fault, and the bytes of the step from the table's own counts.

use palpate::bench::measure::Sampling;
use palpate::bench::tensor_mass::{StepConfig, StepCounts, time_step_on_mesh};
use palpate::dispatch::HostDispatch;
use palpate::fem::material::Material;
use palpate::mesh::MeshReport;
use palpate::mesh::generate::box_mesh;
use palpate::table::build::{BuildOptions, build};
use palpate::table::file::Precision;
use palpate::table::load::TableFile;
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::tensor_mass::{ElasticLaw, Integrator, StvkForm};

#[test]
fn time_step_on_mesh_returns_a_median_and_its_spread() {
    let mesh = box_mesh([3, 3, 3], [0.03; 3]);
    let options = BuildOptions::tensor_mass(
        Material::new(5000.0, 0.4).unwrap(),
        1000.0,
        vec!["z<1e-9".parse().unwrap()],
        Precision::F64,
    );
    let sampling = Sampling {
        warmup: 1,
        samples: 5,
        sample_s: 1e-4,
    };
    let config = StepConfig {
        law: ElasticLaw::StVenantKirchhoff(StvkForm::PerTet),
        incompressibility_n: Some(0.01),
        integrator: Integrator::CentralDifference,
    };
    let report = MeshReport::default();
    let timed = time_step_on_mesh(
        &mesh,
        &report,
        &options,
        &config,
        Precision::F32,
        HostDispatch::detect(),
        &sampling,
    )
    .unwrap();
    let t = timed.timing;
    assert_eq!(t.samples, 5);
    assert!(t.iterations >= 1);
    assert!(0.0 < t.min_s && t.min_s <= t.q1_s && t.q1_s <= t.median_s);
    assert!(t.median_s <= t.q3_s && t.q3_s <= t.max_s);
    assert_eq!(timed.faults, 0);
    // 64 vertices, 162 tets; the counts and bytes of the f32 table.
    let f32_options = BuildOptions {
        precision: Precision::F32,
        ..options
    };
    let file = TableFile::from_bytes(&build(&mesh, &report, &f32_options).unwrap().bytes);
    let counts = StepCounts::of(&TensorMassTable::<f32>::load(file.bytes()).unwrap());
    assert_eq!((counts.vertices, counts.tets), (64, 162));
    assert_eq!(timed.counts, counts);
    assert_eq!(timed.bytes, counts.step_bytes(&config, 4));
    // The penalty's pass reads the tets again: more bytes than without it.
    let plain = StepConfig {
        incompressibility_n: None,
        ..config
    };
    assert!(counts.step_bytes(&plain, 4) < timed.bytes);
}
