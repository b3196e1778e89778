//! Table build time (`host-harness/src/table`): sparse Cholesky (faer, AMD
//! ordering) vs the paper's conjugate-gradient baseline, on tissue cubes of
//! 6³, 12³ and 20³ cells (343, 2197 and 9261 vertices).
//!
//! Target (the table build's speed target): the 12³ cube in at most 2 s on one core, at least 5×
//! faster than scipy's SuperLU computing the same blocks
//! (`tools/reference/scipy_compliance.py`). CG is run on the two smaller
//! sizes only: it already takes seconds at 6³ and grows about as N².
//!
//! Run on one core: `taskset -c 1 cargo bench -p palpate-benches --bench table_build`.

use core::time::Duration;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use palpate::table::build::{DEFAULT_LIST_TOOL_RADIUS_M, TableKindOptions, build};
use palpate::table::compliance::Solver;
use palpate_benches::tissue_cube;

fn table_build(c: &mut Criterion) {
    let mut group = c.benchmark_group("table_build");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(20));
    for (cells, solvers) in [
        (4, &[Solver::Cholesky, Solver::Cg][..]),
        (6, &[Solver::Cholesky, Solver::Cg][..]),
        (12, &[Solver::Cholesky][..]),
        (20, &[Solver::Cholesky][..]),
    ] {
        let (mesh, report, mut options) = tissue_cube(cells);
        for &solver in solvers {
            options.kind = TableKindOptions::Precomputed {
                solver,
                compression: None,
                tool_radius_m: DEFAULT_LIST_TOOL_RADIUS_M,
            };
            let name = format!("{solver:?}").to_lowercase();
            let id = BenchmarkId::new(name, format!("{}v", mesh.positions.len()));
            group.bench_with_input(id, &options, |b, options| {
                b.iter(|| build(&mesh, &report, options).expect("table"))
            });
        }
    }
    group.finish();
}

criterion_group!(benches, table_build);
criterion_main!(benches);
