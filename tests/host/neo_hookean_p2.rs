//! The host's 10-node (P2) compressible neo-Hookean tetrahedron
//! (`palpate::fem::neo_hookean_p2`): forces against central differences of
//! the energy, the tangent against central differences of the forces, rigid
//! motions, a fold between the quadrature points (refused), and the
//! P1 mesh raised to P2 (shared mid-edge nodes). Its Newton solves on the
//! scikit-fem problems are in `neo_hookean_reference`.

use nalgebra::{Matrix3, Rotation3, Vector3};
use palpate::fem::hyperelastic::HyperelasticTet;
use palpate::fem::material::{Material, TetMaterials};
use palpate::fem::neo_hookean_p2::{EDGES, NeoHookeanP2Tet, P2Mesh};
use palpate::fem::newton::{NewtonOptions, StaticProblem, solve_neo_hookean_p2};

/// An irregular tet about 5 cm across (positively oriented), m.
const CORNERS: [[f64; 3]; 4] = [
    [0.0, 0.0, 0.0],
    [0.05, 0.004, -0.003],
    [0.012, 0.043, 0.006],
    [-0.004, 0.009, 0.047],
];

fn material() -> Material {
    Material::new(5000.0, 0.45).expect("material")
}

/// The 10 rest nodes of `CORNERS`: corners, then the midpoints of `EDGES`.
fn rest() -> [[f64; 3]; 10] {
    core::array::from_fn(|n| {
        if n < 4 {
            CORNERS[n]
        } else {
            let [i, j] = EDGES[n - 4];
            ((Vector3::from(CORNERS[i]) + Vector3::from(CORNERS[j])) * 0.5).into()
        }
    })
}

/// The rest nodes deformed by `F = I + g`, moved by `t`, and the mid-edge
/// nodes pushed by `bulge` (m) each along a fixed direction: a quadratic
/// (non-affine) field, so `F` differs between the quadrature points.
fn deformed(g: Matrix3<f64>, t: Vector3<f64>, bulge: f64) -> [[f64; 3]; 10] {
    let f = Matrix3::identity() + g;
    let mut x = rest().map(|p| <[f64; 3]>::from(f * Vector3::from(p) + t));
    for (n, node) in x.iter_mut().enumerate().skip(4) {
        let direction = Vector3::new(1.0, -0.5 * n as f64 / 9.0, 0.3 - 0.1 * n as f64 / 9.0);
        *node = (Vector3::from(*node) + direction * bulge).into();
    }
    x
}

/// Large, non-affine deformations (each `J > 0` at every point).
fn configurations() -> Vec<(&'static str, [[f64; 3]; 10])> {
    let t = Vector3::new(0.01, -0.02, 0.005);
    vec![
        (
            "stretch 1.4, bulged",
            deformed(
                Matrix3::from_diagonal(&Vector3::new(0.4, -0.1, -0.1)),
                t,
                0.004,
            ),
        ),
        (
            "compression J 0.33, bulged",
            deformed(
                Matrix3::from_diagonal(&Vector3::new(-0.5, -0.2, -0.15)),
                t,
                -0.002,
            ),
        ),
        (
            "shear and rotation, bulged",
            deformed(
                Matrix3::new(0.1, 0.35, -0.2, -0.3, 0.15, 0.1, 0.25, -0.1, -0.2),
                t,
                0.003,
            ),
        ),
    ]
}

/// The forces equal minus the central difference of the energy (step 1e-8
/// m, about 1e-6 of the tet's size) within 1e-6 of the largest force: the
/// difference's truncation error is `h²·W'''/6`, about 1e-10 relative, its
/// rounding `ε·W/h` about 1e-8 relative (W ~ 1e-2 J, f ~ 1 N).
#[test]
fn forces_are_minus_the_energy_gradient() {
    let e = NeoHookeanP2Tet::at_rest(&rest(), &material());
    for (name, x) in configurations() {
        assert!(e.admissible(&x), "{name}: J > 0 at every point");
        let f = e.forces_n(&x);
        let scale = f.iter().map(|v| v.amax()).fold(0.0, f64::max);
        let h = 1e-8;
        let mut worst = 0.0f64;
        for v in 0..10 {
            for c in 0..3 {
                let (mut plus, mut minus) = (x, x);
                plus[v][c] += h;
                minus[v][c] -= h;
                let fd = -(e.energy_j(&plus) - e.energy_j(&minus)) / (2.0 * h);
                worst = worst.max((fd - f[v][c]).abs());
            }
        }
        println!("{name}: |f + ∇W| ≤ {worst:.2e} of {scale:.2e} N");
        assert!(scale > 1e-3, "{name}: a loaded configuration");
        assert!(worst <= 1e-6 * scale, "{name}: {worst:e} of {scale:e}");
    }
}

/// The tangent equals minus the central difference of the forces (step
/// 1e-8 m) within 1e-6 of its largest entry (the same error budget as the
/// forces', one derivative higher), and is symmetric to rounding (1e-12).
#[test]
fn tangent_is_minus_the_force_jacobian() {
    let e = NeoHookeanP2Tet::at_rest(&rest(), &material());
    for (name, x) in configurations() {
        let k = e.tangent(&x);
        let scale = k
            .iter()
            .flatten()
            .flatten()
            .flatten()
            .fold(0.0f64, |m, v| m.max(v.abs()));
        let h = 1e-8;
        let (mut worst, mut asymmetry) = (0.0f64, 0.0f64);
        for n in 0..10 {
            for c in 0..3 {
                let (mut plus, mut minus) = (x, x);
                plus[n][c] += h;
                minus[n][c] -= h;
                let (fp, fm) = (e.forces_n(&plus), e.forces_n(&minus));
                for j in 0..10 {
                    for a in 0..3 {
                        let fd = -(fp[j][a] - fm[j][a]) / (2.0 * h);
                        worst = worst.max((fd - k[j][n][a][c]).abs());
                        asymmetry = asymmetry.max((k[j][n][a][c] - k[n][j][c][a]).abs());
                    }
                }
            }
        }
        println!("{name}: |K + ∂f/∂x| ≤ {worst:.2e}, asymmetry {asymmetry:.2e} of {scale:.2e} N/m");
        assert!(worst <= 1e-6 * scale, "{name}: {worst:e} of {scale:e}");
        assert!(
            asymmetry <= 1e-12 * scale,
            "{name}: asymmetry {asymmetry:e}"
        );
    }
}

/// A rigid rotation and translation of the rest nodes stores no energy and
/// gives no force: within 1e-12 of the forces of the stretch (rounding of
/// `F` ≈ R, entries ~1, against strains ~0.1).
#[test]
fn rigid_motion_gives_no_force() {
    let e = NeoHookeanP2Tet::at_rest(&rest(), &material());
    let scale = e
        .forces_n(&configurations()[0].1)
        .iter()
        .map(|v| v.amax())
        .fold(0.0, f64::max);
    let r = Rotation3::from_scaled_axis(Vector3::new(0.7, -1.1, 0.4));
    let t = Vector3::new(0.3, -0.2, 0.15);
    let x = rest().map(|p| <[f64; 3]>::from(r * Vector3::from(p) + t));
    let worst = e.forces_n(&x).iter().map(|v| v.amax()).fold(0.0, f64::max);
    let energy = e.energy_j(&x).abs();
    println!("rigid: |f| ≤ {worst:.2e} N, |W| = {energy:.2e} J (stretch forces {scale:.2e} N)");
    assert!(worst <= 1e-12 * scale, "force {worst:e}");
    assert!(energy <= 1e-15, "energy {energy:e}");
}

/// Two tets sharing a face: the P2 mesh has 5 vertices, 9 distinct edges
/// (one node each, the 3 of the shared face once), every mid-edge node at
/// its edge's midpoint; a mid-edge node is flagged where both its vertices
/// are; loads stay on the vertices.
#[test]
fn p2_mesh_shares_mid_edge_nodes() {
    let positions = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
    ];
    let tets = [[0, 1, 2, 3], [0, 2, 1, 4]];
    let mesh = P2Mesh::new(&positions, &tets);
    assert_eq!(mesh.positions.len(), 5 + 9);
    assert_eq!(mesh.edges.len(), 9);
    for t in &mesh.tets {
        for (n, [i, j]) in EDGES.iter().enumerate() {
            let mid = (Vector3::from(mesh.positions[t[*i] as usize])
                + Vector3::from(mesh.positions[t[*j] as usize]))
                * 0.5;
            assert_eq!(Vector3::from(mesh.positions[t[4 + n] as usize]), mid);
        }
    }
    // The shared face 0-1-2: its edge nodes are the same in both tets.
    let node = |t: usize, a: u32, b: u32| {
        let tet = mesh.tets[t];
        EDGES
            .iter()
            .position(|[i, j]| (tet[*i], tet[*j]) == (a, b) || (tet[*i], tet[*j]) == (b, a))
            .map(|n| tet[4 + n])
            .expect("edge of the tet")
    };
    for (a, b) in [(0, 1), (1, 2), (0, 2)] {
        assert_eq!(node(0, a, b), node(1, a, b));
    }
    let flags = mesh.node_flags(&[true, true, true, false, false]);
    assert_eq!(flags.iter().filter(|&&f| f).count(), 3 + 3);
    let loads = mesh.node_loads(&[[0.0; 3], [0.0; 3], [0.0; 3], [1.0, 2.0, 3.0], [0.0; 3]]);
    assert_eq!(loads.len(), 14);
    assert_eq!(loads[3], [1.0, 2.0, 3.0]);
    assert!(loads[5..].iter().all(|l| *l == [0.0; 3]));
}

/// A fold between the quadrature points: the unit corner tet mapped by
/// `φ(X) = (x, y, z − c z²)`, exactly interpolated by the P2 nodes, has
/// `F = diag(1, 1, 1 − 2cz)`. At `c = 0.7`, `J = 1 − 2cz` is 0.18 and 0.81
/// at the quadrature points (`z = α, β`: the element's energy is finite)
/// but −0.4 at the apex: the element is folded over inside, and only the
/// nodes see it. At `c = 0.4` (`J ≥ 0.2` at the apex) it keeps its
/// orientation: the check rejects the fold, not a strong compression.
/// Newton on this one tet, every node prescribed at `φ` but the mid-edge
/// node of the base edge 0–1 (free), converges, and `solve_neo_hookean_p2`
/// refuses the folded equilibrium (without the check it returned it), not
/// the unfolded one.
#[test]
fn a_fold_between_the_quadrature_points_is_refused() {
    let corners = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let nodes: [[f64; 3]; 10] = core::array::from_fn(|n| {
        if n < 4 {
            corners[n]
        } else {
            let [i, j] = EDGES[n - 4];
            ((Vector3::from(corners[i]) + Vector3::from(corners[j])) * 0.5).into()
        }
    });
    let e = NeoHookeanP2Tet::at_rest(&nodes, &material());
    let fold = |c: f64| nodes.map(|[x, y, z]| [x, y, z - c * z * z]);
    assert!(e.admissible(&fold(0.7)) && e.energy_j(&fold(0.7)).is_finite());
    assert!(!e.keeps_orientation(&fold(0.7)), "a folded element kept");
    assert!(e.keeps_orientation(&fold(0.4)));
    let solve = |c: f64| {
        let prescribed: Vec<(u32, [f64; 3])> = (0..10u32)
            .filter(|&n| n != 4)
            .map(|n| {
                let (x, p) = (fold(c)[n as usize], nodes[n as usize]);
                (n, [x[0] - p[0], x[1] - p[1], x[2] - p[2]])
            })
            .collect();
        let materials = TetMaterials::uniform(material(), 1);
        let problem = StaticProblem::<10> {
            positions: &nodes,
            tets: &[core::array::from_fn(|n| n as u32)],
            materials: &materials,
            fixed: &[false; 10],
            prescribed: &prescribed,
            loads_n: &[],
        };
        solve_neo_hookean_p2(
            &problem,
            &NewtonOptions {
                load_steps: 4,
                ..NewtonOptions::default()
            },
        )
    };
    let refused = solve(0.7).expect_err("the folded equilibrium was returned");
    assert!(
        format!("{refused:#}").contains("folds tet 0"),
        "{refused:#}"
    );
    solve(0.4).expect("the unfolded equilibrium");
}
