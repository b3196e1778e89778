//! P1 element, global assembly and the direct Dirichlet solve against the
//! independent scikit-fem reference (`tests/reference/linear/`).

// Index loops mirror the tensor notation of MODELS.md.
#![allow(clippy::needless_range_loop)]

use palpate::fem::assembly::{FreeOrdering, assemble_stiffness};
use palpate::fem::element::{element_stiffness, shape_gradients};
use palpate::fem::material::{Material, TetMaterials};
use palpate::fem::static_solve::solve_prescribed;
use palpate_tests::{
    max_entry_difference, read_reference_json, read_reference_stiffness, read_reference_tetgen,
    rel_max_diff,
};

type Ke = [[[[f64; 3]; 3]; 4]; 4];

const TET: [[f64; 3]; 4] = [
    [0.01, -0.02, 0.005],
    [0.06, 0.01, -0.01],
    [0.015, 0.045, 0.02],
    [0.02, 0.0, 0.055],
];

fn material() -> Material {
    Material::new(5000.0, 0.45).unwrap()
}

fn k_max(k: &Ke) -> f64 {
    k.iter()
        .flatten()
        .flatten()
        .flatten()
        .fold(0.0f64, |m, x| m.max(x.abs()))
}

/// `f_j = Σ_k K_jk u_k`.
fn apply(k: &Ke, u: &[[f64; 3]; 4]) -> [[f64; 3]; 4] {
    let mut f = [[0.0; 3]; 4];
    for j in 0..4 {
        for kk in 0..4 {
            for a in 0..3 {
                for b in 0..3 {
                    f[j][a] += k[j][kk][a][b] * u[kk][b];
                }
            }
        }
    }
    f
}

#[test]
fn material_validation_and_lame() {
    assert!(Material::new(0.0, 0.3).is_err());
    assert!(Material::new(-1.0, 0.3).is_err());
    assert!(Material::new(f64::NAN, 0.3).is_err());
    assert!(Material::new(f64::INFINITY, 0.3).is_err());
    assert!(Material::new(1.0, 0.5).is_err());
    assert!(Material::new(1.0, -0.1).is_err());
    assert!(Material::new(1.0, 0.0).is_ok());
    let (l, mu) = material().lame();
    assert!((l - 15517.24137931035).abs() < 1e-9);
    assert!((mu - 1724.1379310344828).abs() < 1e-10);
}

#[test]
fn shape_gradients_are_barycentric_gradients() {
    let (a, v) = shape_gradients(&TET);
    assert!(v > 0.0);
    // ∇Λ_j · (p_k - p_0) = δ_jk - δ_j0
    for j in 0..4 {
        for k in 1..4 {
            let d: f64 = (0..3).map(|c| a[j][c] * (TET[k][c] - TET[0][c])).sum();
            let want = f64::from(u8::from(j == k)) - f64::from(u8::from(j == 0));
            assert!((d - want).abs() < 1e-12, "j={j} k={k} got {d}");
        }
    }
    // Swapping two vertices flips the volume sign.
    let mut q = TET;
    q.swap(2, 3);
    assert!((shape_gradients(&q).1 + v).abs() < 1e-18);
}

#[test]
fn element_rigid_motions_give_zero_force() {
    let k = element_stiffness(&TET, &material());
    let scale = k_max(&k);
    let t = [0.3, -0.7, 0.5];
    let f = apply(&k, &[t; 4]);
    for fj in f {
        for x in fj {
            assert!(x.abs() <= 1e-12 * scale, "translation force {x}");
        }
    }
    // Infinitesimal rotation u = ω × x.
    let w = [0.2, -0.4, 0.9];
    let u = TET.map(|p| {
        [
            w[1] * p[2] - w[2] * p[1],
            w[2] * p[0] - w[0] * p[2],
            w[0] * p[1] - w[1] * p[0],
        ]
    });
    let umax = u.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    for fj in apply(&k, &u) {
        for x in fj {
            assert!(x.abs() <= 1e-12 * scale * umax, "rotation force {x}");
        }
    }
}

#[test]
fn element_symmetry_and_row_sums() {
    let k = element_stiffness(&TET, &material());
    let scale = k_max(&k);
    for j in 0..4 {
        for kk in 0..4 {
            for a in 0..3 {
                for b in 0..3 {
                    assert!((k[j][kk][a][b] - k[kk][j][b][a]).abs() <= 1e-14 * scale);
                }
            }
        }
        for a in 0..3 {
            for b in 0..3 {
                let s: f64 = (0..4).map(|kk| k[j][kk][a][b]).sum();
                assert!(s.abs() <= 1e-12 * scale, "row block sum {s}");
            }
        }
    }
    // Positive semi-definite: energy of a random field is >= 0.
    let u = [
        [0.1, 0.2, -0.3],
        [0.0, 0.5, 0.1],
        [-0.2, 0.1, 0.0],
        [0.3, -0.1, 0.2],
    ];
    let f = apply(&k, &u);
    let e: f64 = (0..4)
        .map(|j| (0..3).map(|a| f[j][a] * u[j][a]).sum::<f64>())
        .sum();
    assert!(e > 0.0);
}

#[test]
fn element_matches_energy_finite_difference() {
    // K = Hessian of W = V(λ/2 (tr ε)² + μ ε:ε); W is quadratic, so central
    // differences of the gradient are exact up to rounding.
    let m = material();
    let (lam, mu) = m.lame();
    let (a, v) = shape_gradients(&TET);
    let energy = |u: &[[f64; 3]; 4]| {
        let mut g = [[0.0; 3]; 3];
        for j in 0..4 {
            for r in 0..3 {
                for c in 0..3 {
                    g[r][c] += u[j][r] * a[j][c];
                }
            }
        }
        let eps = |r: usize, c: usize| 0.5 * (g[r][c] + g[c][r]);
        let tr = eps(0, 0) + eps(1, 1) + eps(2, 2);
        let mut ee = 0.0;
        for r in 0..3 {
            for c in 0..3 {
                ee += eps(r, c) * eps(r, c);
            }
        }
        v * (0.5 * lam * tr * tr + mu * ee)
    };
    let k = element_stiffness(&TET, &m);
    let scale = k_max(&k);
    let h = 1e-3;
    for j in 0..4 {
        for kk in 0..4 {
            for r in 0..3 {
                for c in 0..3 {
                    let e = |sj: f64, sk: f64| {
                        let mut u = [[0.0; 3]; 4];
                        u[j][r] += sj * h;
                        u[kk][c] += sk * h;
                        energy(&u)
                    };
                    let fd =
                        (e(1.0, 1.0) - e(1.0, -1.0) - e(-1.0, 1.0) + e(-1.0, -1.0)) / (4.0 * h * h);
                    assert!(
                        (fd - k[j][kk][r][c]).abs() <= 1e-7 * scale,
                        "({j},{kk},{r},{c})"
                    );
                }
            }
        }
    }
}

fn cube_k() -> faer::sparse::SparseColMat<usize, f64> {
    let (p, t) = read_reference_tetgen("cube");
    assemble_stiffness(&p, &t, &TetMaterials::uniform(material(), t.len()))
}

#[test]
fn global_k_matches_reference_csv() {
    let k = cube_k();
    let reference = read_reference_stiffness();
    assert_eq!(reference.len(), 18372);
    let scale = reference.values().fold(0.0f64, |m, x| m.max(x.abs()));
    assert_eq!(k.nrows(), 648);
    let mut ours = std::collections::HashMap::new();
    for t in k.triplet_iter() {
        ours.insert((t.row, t.col), *t.val);
    }
    let worst = max_entry_difference(&ours, &reference);
    println!("max |K - K_ref| / max|K_ref| = {:e}", worst / scale);
    assert!(worst <= 1e-12 * scale, "relative {:e}", worst / scale);
}

#[test]
fn patch_test_linear_field_gives_zero_interior_force() {
    let (p, t) = read_reference_tetgen("cube");
    let k = cube_k();
    let g = [[0.3, -0.1, 0.7], [0.2, 0.5, -0.4], [-0.6, 0.1, 0.25]];
    let u: Vec<f64> = p
        .iter()
        .flat_map(|x| (0..3).map(move |a| (0..3).map(|b| g[a][b] * x[b]).sum::<f64>()))
        .collect();
    let mut f = vec![0.0f64; u.len()];
    for tr in k.triplet_iter() {
        f[tr.row] += tr.val * u[tr.col];
    }
    let scale = k.val().iter().fold(0.0f64, |m, x| m.max(x.abs()))
        * u.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let boundary = palpate_tests::boundary_vertices(p.len(), &t);
    let mut interior_checked = 0;
    for v in 0..p.len() {
        if boundary.binary_search(&(v as u32)).is_err() {
            interior_checked += 1;
            for a in 0..3 {
                assert!(
                    f[3 * v + a].abs() <= 1e-10 * scale,
                    "vertex {v}: {}",
                    f[3 * v + a]
                );
            }
        }
    }
    assert_eq!(interior_checked, 64);
    // Every block row of K sums to zero (rigid translations).
    let mut row_sum = vec![[0.0f64; 3]; u.len()];
    for tr in k.triplet_iter() {
        row_sum[tr.row][tr.col % 3] += tr.val;
    }
    let kmax = k.val().iter().fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(row_sum.iter().flatten().all(|s| s.abs() <= 1e-12 * kmax));
}

fn vec3s(v: &serde_json::Value) -> Vec<[f64; 3]> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|r| {
            let r = r.as_array().unwrap();
            [0, 1, 2].map(|c| r[c].as_f64().unwrap())
        })
        .collect()
}

fn flat(v: &[[f64; 3]]) -> Vec<f64> {
    v.iter().flatten().copied().collect()
}

#[test]
fn static_solve_matches_reference_contacts() {
    let (p, t) = read_reference_tetgen("cube");
    let fixed: Vec<bool> = p.iter().map(|x| x[2] == 0.0).collect();
    assert_eq!(fixed.iter().filter(|&&f| f).count(), 36);
    let r = read_reference_json("linear/cube_contact.json");

    let single = &r["single_contact"];
    let v = single["vertex"].as_u64().unwrap() as u32;
    let d = vec3s(&serde_json::json!([single["imposed_displacement"]]))[0];
    let (u, f) = solve_prescribed(
        &p,
        &t,
        &TetMaterials::uniform(material(), t.len()),
        &fixed,
        &[(v, d)],
    )
    .unwrap();
    let ref_u = vec3s(&single["displacements"]);
    let ref_f = vec3s(&serde_json::json!([single["force"]]));
    let eu = rel_max_diff(&flat(&u), &flat(&ref_u));
    let ef = rel_max_diff(&flat(&f), &flat(&ref_f));
    println!("single contact: displacement rel {eu:e}, force rel {ef:e}");
    assert!(eu <= 1e-10 && ef <= 1e-10);
    assert!((f[0][2] - (-13.62270)).abs() < 1e-5);

    let two = &r["two_contacts"];
    let vs: Vec<u32> = two["vertices"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_u64().unwrap() as u32)
        .collect();
    let ds = vec3s(&two["imposed_displacements"]);
    let pres: Vec<(u32, [f64; 3])> = vs.iter().copied().zip(ds.iter().copied()).collect();
    let (u, f) = solve_prescribed(
        &p,
        &t,
        &TetMaterials::uniform(material(), t.len()),
        &fixed,
        &pres,
    )
    .unwrap();
    let eu = rel_max_diff(&flat(&u), &flat(&vec3s(&two["displacements"])));
    let ef = rel_max_diff(&flat(&f), &flat(&vec3s(&two["forces"])));
    println!("two contacts: displacement rel {eu:e}, force rel {ef:e}");
    assert!(eu <= 1e-10 && ef <= 1e-10);
}

#[test]
fn static_solve_rejects_bad_input() {
    let (p, t) = read_reference_tetgen("cube");
    let m = TetMaterials::uniform(material(), t.len());
    let fixed: Vec<bool> = p.iter().map(|x| x[2] == 0.0).collect();
    assert!(
        solve_prescribed(&p, &t, &m, &fixed, &[(0, [0.0; 3])]).is_err(),
        "fixed vertex"
    );
    assert!(solve_prescribed(&p, &t, &m, &fixed, &[(194, [0.0; 3]), (194, [0.0; 3])]).is_err());
    assert!(solve_prescribed(&p, &t, &m, &fixed, &[(999, [0.0; 3])]).is_err());
    assert!(solve_prescribed(&p, &t, &m, &fixed[1..], &[]).is_err());
    // Nothing holds the body: singular.
    let none = vec![false; p.len()];
    assert!(solve_prescribed(&p, &t, &m, &none, &[]).is_err());
    // Materials for another mesh.
    let fewer = TetMaterials::uniform(material(), t.len() - 1);
    assert!(solve_prescribed(&p, &t, &fewer, &fixed, &[]).is_err());
}

#[test]
fn free_ordering_layout() {
    // 6 vertices: 0,1 fixed; surface {1,2,4,5} (unsorted, duplicate).
    let fixed = [true, true, false, false, false, false];
    let o = FreeOrdering::new(6, &fixed, &[5, 1, 2, 4, 2]);
    assert_eq!(o.touchable_count, 3);
    assert_eq!(o.free_vertex, vec![2, 4, 5, 3]);
    assert_eq!(
        o.vertex_slot,
        vec![None, None, Some(0), Some(3), Some(1), Some(2)]
    );
    assert_eq!(o.free_count(), 4);
}
