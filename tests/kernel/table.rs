//! Table loading (`palpate_kernel::table`): round trip, corruption detection,
//! and every structural error a well-formed checksum cannot hide.

use palpate::table::file::Precision;
use palpate::table::load::TableFile;
use palpate_kernel::table::format::{HEADER_LEN, SECTION_ENTRY_LEN, SectionKind};
use palpate_kernel::{LoadError, PrecomputedTable};
use palpate_tests::{TinyTable, reference_cube_table};

fn load32(bytes: &[u8]) -> Result<(), LoadError> {
    let file = TableFile::from_bytes(bytes);
    PrecomputedTable::<f32>::load(file.bytes()).map(|_| ())
}

#[test]
fn round_trip_counts() {
    let file = reference_cube_table(Precision::F32);
    let t = PrecomputedTable::<f32>::load(file.bytes()).unwrap();
    assert_eq!(t.vertex_count(), 216);
    assert_eq!(t.free_count(), 180);
    assert_eq!(t.touchable_count(), 116);
    assert_eq!(t.surface_triangles().len(), 300);
    assert_eq!(t.young_pa(), 5000.0);
    assert_eq!(t.poisson(), 0.45);
    assert!(t.is_fixed(0) && !t.is_fixed(194));
    // f64 table of the same mesh: same counts, twice the compliance bytes.
    let file64 = reference_cube_table(Precision::F64);
    assert!(PrecomputedTable::<f64>::load(file64.bytes()).is_ok());
    assert_eq!(
        PrecomputedTable::<f32>::load(file64.bytes()).unwrap_err(),
        LoadError::ScalarMismatch {
            table: 8,
            requested: 4
        }
    );
}

/// CRC-32 detects every single-bit error; check that each one in the header
/// and directory is refused, and a seeded sample of 4000 in the payload.
#[test]
fn every_header_bit_flip_and_sampled_payload_flips_are_detected() {
    let file = reference_cube_table(Precision::F32);
    let original = file.bytes().to_vec();
    let header_bits = (HEADER_LEN + 6 * SECTION_ENTRY_LEN) * 8;
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut payload_bits = Vec::new();
    for _ in 0..4000 {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        payload_bits.push(header_bits + (state as usize) % (original.len() * 8 - header_bits));
    }
    for bit in (0..header_bits).chain(payload_bits) {
        let mut bytes = original.clone();
        bytes[bit / 8] ^= 1 << (bit % 8);
        assert!(load32(&bytes).is_err(), "bit flip {bit} not detected");
    }
}

#[test]
fn truncation_padding_and_garbage_are_refused() {
    let file = reference_cube_table(Precision::F32);
    let bytes = file.bytes();
    assert_eq!(load32(&bytes[..10]), Err(LoadError::TooShort { len: 10 }));
    assert!(matches!(
        load32(&bytes[..bytes.len() - 1]),
        Err(LoadError::LengthMismatch { .. })
    ));
    let mut padded = bytes.to_vec();
    padded.push(0);
    assert!(matches!(
        load32(&padded),
        Err(LoadError::LengthMismatch { .. })
    ));
    assert_eq!(load32(&[0u8; 200]), Err(LoadError::BadMagic));
}

#[test]
fn misaligned_buffer_is_refused() {
    let file = reference_cube_table(Precision::F32);
    let mut shifted = vec![0u8; file.bytes().len() + 1];
    shifted[1..].copy_from_slice(file.bytes());
    // `TableFile` aligns to 16, so byte 1 of its buffer is odd-aligned.
    let holder = TableFile::from_bytes(&shifted);
    let err = PrecomputedTable::<f32>::load(&holder.bytes()[1..]).unwrap_err();
    assert!(matches!(err, LoadError::Misaligned { .. }), "{err}");
}

#[test]
fn structural_errors_behind_a_valid_checksum() {
    assert_eq!(load32(&TinyTable::new().bytes()), Ok(()));

    let mut t = TinyTable::new();
    t.surface[4][8] = f64::NAN;
    assert_eq!(
        load32(&t.bytes()),
        Err(LoadError::NonFinite {
            kind: SectionKind::ComplianceSurface,
            index: 4
        })
    );

    let mut t = TinyTable::new();
    t.surface[5][0] = -1e-4; // C_22 (index 2·3/2 + 2 = 5) not positive definite
    assert_eq!(
        load32(&t.bytes()),
        Err(LoadError::NotPositiveDefinite { touchable: 2 })
    );

    let mut t = TinyTable::new();
    t.surface[0][1] = 5e-5; // C_00 not symmetric
    assert_eq!(
        load32(&t.bytes()),
        Err(LoadError::NotPositiveDefinite { touchable: 0 })
    );

    let mut t = TinyTable::new();
    t.free_vertex.swap(0, 1);
    assert_eq!(
        load32(&t.bytes()),
        Err(LoadError::BadVertexMap { vertex: 1 })
    );

    let mut t = TinyTable::new();
    t.triangles[0][2] = 5;
    assert_eq!(
        load32(&t.bytes()),
        Err(LoadError::BadTriangle { triangle: 0 })
    );

    let mut t = TinyTable::new();
    t.positions[3][1] = f64::INFINITY;
    assert_eq!(
        load32(&t.bytes()),
        Err(LoadError::NonFinite {
            kind: SectionKind::RestPositions,
            index: 3
        })
    );

    // The plane record's barycentric frame (format 5): each gradient must
    // weigh the corners 1 and 0 and lie in the plane. Triangle [1, 2, 3]
    // spans e₁ = (−1, 1, 0), e₂ = (−1, 0, 1): g₁ = (−1, 2, −1)/3.
    let t = TinyTable::new();
    let g1 = t.bytes_with_index(|c| {
        let g1 = c.planes[0][4..7].to_vec();
        assert!((g1[0] + 1.0 / 3.0).abs() < 1e-12, "{g1:?}");
        assert!((g1[1] - 2.0 / 3.0).abs() < 1e-12, "{g1:?}");
        assert!((g1[2] + 1.0 / 3.0).abs() < 1e-12, "{g1:?}");
    });
    assert_eq!(load32(&g1), Ok(()));
    for (at, by) in [(4, 1e-3), (8, -1e-3)] {
        // g₁ₓ off by 1e-3 (g₁ weighs e₁ 1.001), or g₂ᵧ (g₂ weighs e₁
        // −0.001): beyond the loader's 1e-4.
        let bad = t.bytes_with_index(|c| c.planes[0][at] += by);
        assert_eq!(
            load32(&bad),
            Err(LoadError::BadSurfacePlane { triangle: 0 }),
            "scalar {at}"
        );
    }

    let mut t = TinyTable::new();
    t.young_pa = -1.0;
    assert_eq!(load32(&t.bytes()), Err(LoadError::BadMaterial));

    let mut t = TinyTable::new();
    t.surface.pop();
    assert_eq!(
        load32(&t.bytes()),
        Err(LoadError::SectionSize {
            kind: SectionKind::ComplianceSurface
        })
    );
}

#[test]
fn info_reports_counts_and_checksum() {
    let file = reference_cube_table(Precision::F32);
    let info = file.info("cube.tbl").unwrap();
    for line in [
        "vertices: 216",
        "tets: 750",
        "fixed vertices: 36",
        "touchable (free surface) vertices: 116",
        "young modulus: 5000 Pa",
        "checksum: ok",
        "validation: ok",
    ] {
        assert!(info.contains(line), "missing '{line}' in\n{info}");
    }
    let mut bytes = file.bytes().to_vec();
    let last = bytes.len() - 10;
    bytes[last] ^= 0x10;
    let info = TableFile::from_bytes(&bytes).info("bad.tbl").unwrap_err();
    assert!(info.contains("checksum: MISMATCH"), "{info}");
}

/// The barycentric weights from the stored frame (format 5) equal the
/// ratios of sub-triangle areas (cross products over the corners, the
/// formula the frame replaced), on every surface triangle of the reference
/// cube (f64), at its corners, its centroid, a point outside it and
/// points off its plane (the frame weighs the projection): to 1e-9, the
/// f64 rounding of a few products of unit-sized numbers with margin.
#[test]
fn frame_weights_are_the_area_ratios() {
    use nalgebra::Vector3;
    use palpate_kernel::table::TriangleIndex;
    let file = reference_cube_table(Precision::F64);
    let table = PrecomputedTable::<f64>::load(file.bytes()).unwrap();
    let index = table.surface_index();
    let positions = table.rest_positions();
    let corner = |v: u32| Vector3::from(positions[v as usize]);
    let triangles = table.surface_triangles();
    assert!(triangles.len() > 100);
    for (t, tri) in triangles.iter().enumerate() {
        let [a, b, c] = tri.map(corner);
        let m = (b - a).cross(&(c - a));
        let n = m.normalize();
        let area = |p: &Vector3<f64>, q: &Vector3<f64>, x: &Vector3<f64>| {
            (p - x).cross(&(q - x)).dot(&n) / m.norm()
        };
        let centroid = (a + b + c) / 3.0;
        let outside = a * 1.5 - centroid * 0.5;
        let points = [
            a,
            b,
            c,
            centroid,
            outside,
            centroid + n * 0.01,
            outside - n * 0.3,
        ];
        let id = TriangleIndex::new(t as u32, triangles.len()).unwrap();
        for x in points {
            let on = x - n * n.dot(&(x - a));
            let want = [area(&b, &c, &on), area(&c, &a, &on), area(&a, &b, &on)];
            let got = index.weights(id, positions, &x).unwrap();
            for (g, w) in got.iter().zip(want) {
                assert!(
                    (g - w).abs() < 1e-9,
                    "triangle {t} at {x:?}: {got:?} vs {want:?}"
                );
            }
        }
    }
}
