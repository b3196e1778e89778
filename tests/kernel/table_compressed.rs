//! Compressed compliance tables in the kernel (`kernel/src/table/compressed.rs`; the format's
//! compressed compliance in `kernel/src/table/format/encoding.rs`): the binary16 decode against
//! hand-computed bit patterns and, for every code, against the formula evaluated in f64; the
//! kept-block rank against a plain count; the blocks the view decodes against the codes and
//! scales written; and every refusal of a bad compressed table, behind a valid checksum, with
//! the error that names what is wrong.

use palpate::table::compress::{
    BlockCode, CompressedCompliance, Compression, ContactBlocks, encode, kept_bitmap,
};
use palpate::table::file::Precision;
use palpate::table::load::TableFile;
use palpate_kernel::table::ComplianceBlocks;
use palpate_kernel::table::format::{
    BlockEncoding, SectionKind, f16_to_f32, is_kept, kept_position, kept_rank, surface_block_index,
};
use palpate_kernel::{LoadError, PrecomputedTable};
use palpate_tests::TinyTable;

fn load32(bytes: &[u8]) -> Result<(), LoadError> {
    let file = TableFile::from_bytes(bytes);
    PrecomputedTable::<f32>::load(file.bytes()).map(|_| ())
}

/// `t`'s compliance coded with `code`, nothing dropped, the contact blocks coded.
fn coded(t: &TinyTable, code: BlockCode) -> CompressedCompliance {
    let compression = Compression {
        code,
        drop_below: 0.0,
        contact: ContactBlocks::Coded,
        tolerance: palpate::table::hmatrix::DEFAULT_TOLERANCE,
    };
    encode(&t.compliance(), t.touchable_count, &compression).expect("encode")
}

/// [`TinyTable::with_interior`] with its compliance coded by `code`.
fn tiny(code: BlockCode) -> TinyTable {
    let mut t = TinyTable::with_interior();
    t.compressed = Some(coded(&t, code));
    t
}

fn part(t: &mut TinyTable, surface: bool) -> &mut palpate::table::compress::CodedPart {
    let c = t.compressed.as_mut().expect("compressed");
    if surface {
        c.surface.as_mut().expect("coded surface")
    } else {
        &mut c.interior
    }
}

#[test]
fn f16_decode_matches_hand_computed_bit_patterns() {
    // (code, value), from sign, exponent (bias 15) and fraction by hand; exact in f64 (and f32).
    let cases: [(u16, f64); 12] = [
        (0x0000, 0.0),                       // +0
        (0x3c00, 1.0),                       // e = 15, f = 0
        (0xc000, -2.0),                      // sign, e = 16
        (0x3555, 0.333_251_953_125),         // e = 13: 2^-2 (1 + 341/1024) = 1365/4096
        (0x5640, 100.0),                     // e = 21: 2^6 (1 + 576/1024)
        (0x3bff, 0.999_511_718_75),          // e = 14: 2^-1 (1 + 1023/1024)
        (0x7bff, 65504.0),                   // largest finite: 2^15 (1 + 1023/1024)
        (0x0400, 6.103_515_625e-5),          // smallest normal, 2^-14
        (0x03ff, 6.097_555_160_522_461e-5),  // largest subnormal, 1023 · 2^-24
        (0x0200, 3.051_757_812_5e-5),        // subnormal 512 · 2^-24 = 2^-15
        (0x0001, 5.960_464_477_539_063e-8),  // smallest subnormal, 2^-24
        (0x8001, -5.960_464_477_539_063e-8), // its negative
    ];
    for (code, value) in cases {
        assert_eq!(
            f64::from(f16_to_f32(code)).to_bits(),
            value.to_bits(),
            "{code:#06x}"
        );
    }
    assert_eq!(f16_to_f32(0x8000).to_bits(), (-0.0f32).to_bits());
    assert_eq!(f16_to_f32(0x7c00), f32::INFINITY);
    assert_eq!(f16_to_f32(0xfc00), f32::NEG_INFINITY);
    assert!(f16_to_f32(0x7e00).is_nan() && f16_to_f32(0xfd01).is_nan());
    // Every finite code against (-1)^s 2^(e-15) (1 + f/1024), or f 2^-24 for e = 0, in f64.
    for code in 0..=u16::MAX {
        let (e, f) = (i32::from((code >> 10) & 0x1f), f64::from(code & 0x3ff));
        if e == 31 {
            continue;
        }
        let magnitude = if e == 0 {
            f * 2f64.powi(-24)
        } else {
            2f64.powi(e - 15) * (1.0 + f / 1024.0)
        };
        let value = if code & 0x8000 != 0 {
            -magnitude
        } else {
            magnitude
        };
        assert_eq!(f64::from(f16_to_f32(code)), value, "{code:#06x}");
        assert_eq!(f16_to_f32(code).is_sign_negative(), code & 0x8000 != 0);
    }
}

#[test]
fn kept_rank_counts_the_bits_before() {
    let mut state = 0x2545_F491_4F6C_DD1Du64;
    let flags: Vec<bool> = (0..1000)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            !state.is_multiple_of(3)
        })
        .collect();
    let kept = kept_bitmap(&flags);
    assert_eq!(kept.len(), 1000usize.div_ceil(32));
    let mut before = 0;
    for (j, &f) in flags.iter().enumerate() {
        assert_eq!(kept_rank(&kept, j), Some(before), "block {j}");
        assert_eq!(is_kept(&kept, j), f);
        assert_eq!(kept_position(&kept, j), f.then_some(before));
        before += usize::from(f);
    }
    // Past the bitmap: nothing.
    assert_eq!(kept_rank(&kept, 32 * kept.len()), None);
    assert!(!is_kept(&kept, 32 * kept.len()));
}

/// The blocks the view gives are the codes written times their column's scale (the same f32
/// product), a dropped block zero; the stored counts and encodings are the table's.
#[test]
fn decoded_blocks_are_the_codes_times_their_scales() {
    for code in [BlockCode::F16, BlockCode::Q16] {
        let mut t = tiny(code);
        // Drop interior block 1 (column 1).
        let interior = part(&mut t, false);
        interior.codes.remove(1);
        interior.kept = Some(kept_bitmap(&[true, false, true, true]));
        let file = TableFile::from_bytes(&t.bytes());
        let table = PrecomputedTable::<f32>::load(file.bytes()).expect("load");
        let written = t.compressed.as_ref().expect("compressed");
        assert_eq!(table.compression(), Some(&written.record));
        let value = |c: u16| match code {
            BlockCode::F16 => f16_to_f32(c),
            BlockCode::Q16 => f32::from(c.cast_signed()),
            BlockCode::Hmatrix | BlockCode::HmatrixQ16 => unreachable!("16-bit codes only"),
        };
        let expect = |codes: &[u16; 9], scale: f64| codes.map(|c| value(c) * scale as f32);
        let surface = table.surface_blocks();
        assert_eq!(surface.encoding(), code.encoding());
        assert!(surface.as_dense().is_none());
        assert_eq!((surface.len(), surface.stored_len()), (10, 10));
        let coded_surface = written.surface.as_ref().expect("coded");
        for k in 0..4 {
            for n in 0..=k {
                let j = surface_block_index(n, k);
                let want = expect(&coded_surface.codes[j], coded_surface.scales[k]);
                assert_eq!(surface.block(j, k), Some(want), "surface ({n}, {k})");
            }
        }
        let interior = table.interior_blocks();
        assert_eq!((interior.len(), interior.stored_len()), (4, 3));
        let coded_interior = &written.interior;
        for (k, stored) in [(0, Some(0)), (1, None), (2, Some(1)), (3, Some(2))] {
            let want = stored.map_or([0.0; 9], |p| {
                expect(&coded_interior.codes[p], coded_interior.scales[k])
            });
            assert_eq!(interior.block(k, k), Some(want), "interior column {k}");
            assert_eq!(interior.is_stored(k), stored.is_some());
        }
        assert_eq!(interior.block(4, 3), None);
        assert_eq!(surface.block(10, 3), None);
        assert!(matches!(surface, ComplianceBlocks::Coded(_)));
    }
}

#[test]
fn bad_scales_and_codes_are_refused() {
    for code in [BlockCode::F16, BlockCode::Q16] {
        assert_eq!(load32(&tiny(code).bytes()), Ok(()));
        for (surface, bad) in [
            (true, 0.0),
            (true, f64::NAN),
            (false, -1.0),
            (false, f64::INFINITY),
            // Finite, but a code near the largest (65504 in f16, 32767
            // in q16) times it passes f32's 3.4e38.
            (true, 1e35),
            (false, 3e34),
        ] {
            let mut t = tiny(code);
            part(&mut t, surface).scales[2] = bad;
            let kind = if surface {
                SectionKind::SurfaceScale
            } else {
                SectionKind::InteriorScale
            };
            assert_eq!(
                load32(&t.bytes()),
                Err(LoadError::BadScale { kind, column: 2 }),
                "{code:?} {bad}"
            );
        }
    }
    // f16: an infinity or a NaN.
    for bad in [0x7c00, 0xfc00, 0x7e00, 0x7c01] {
        let mut t = tiny(BlockCode::F16);
        part(&mut t, true).codes[3][4] = bad;
        assert_eq!(
            load32(&t.bytes()),
            Err(LoadError::NonFinite {
                kind: SectionKind::SurfaceCodes,
                index: 3
            })
        );
        let mut t = tiny(BlockCode::F16);
        part(&mut t, false).codes[2][8] = bad;
        assert_eq!(
            load32(&t.bytes()),
            Err(LoadError::NonFinite {
                kind: SectionKind::InteriorCodes,
                index: 2
            })
        );
    }
    // q16: -32768, outside the symmetric range; -32767 and 0x8000 as f16 (-0) are fine.
    let mut t = tiny(BlockCode::Q16);
    part(&mut t, true).codes[5][0] = 0x8000;
    assert_eq!(
        load32(&t.bytes()),
        Err(LoadError::BadCode {
            kind: SectionKind::SurfaceCodes,
            index: 5
        })
    );
    let mut t = tiny(BlockCode::Q16);
    part(&mut t, false).codes[1][1] = 0x8001;
    assert_eq!(load32(&t.bytes()), Ok(()));
    let mut t = tiny(BlockCode::F16);
    part(&mut t, false).codes[1][1] = 0x8000;
    assert_eq!(load32(&t.bytes()), Ok(()));
}

#[test]
fn bad_kept_blocks_are_refused() {
    let dropped = |t: &mut TinyTable| {
        let interior = part(t, false);
        interior.codes.remove(1);
        interior.kept = Some(kept_bitmap(&[true, false, true, true]));
    };
    let mut t = tiny(BlockCode::Q16);
    dropped(&mut t);
    assert_eq!(load32(&t.bytes()), Ok(()));
    // A rank that is not the bits before its word.
    let mut t = tiny(BlockCode::Q16);
    dropped(&mut t);
    part(&mut t, false).kept.as_mut().expect("kept")[0][1] = 1;
    let bad_interior = LoadError::BadKeptBlocks {
        kind: SectionKind::InteriorKept,
        word: 0,
    };
    assert_eq!(load32(&t.bytes()), Err(bad_interior));
    // A bit past the 4 blocks.
    let mut t = tiny(BlockCode::Q16);
    dropped(&mut t);
    part(&mut t, false).kept.as_mut().expect("kept")[0][0] |= 1 << 4;
    assert_eq!(load32(&t.bytes()), Err(bad_interior));
    // Bits that do not count the codes.
    let mut t = tiny(BlockCode::Q16);
    dropped(&mut t);
    part(&mut t, false).codes.pop();
    assert_eq!(
        load32(&t.bytes()),
        Err(LoadError::SectionSize {
            kind: SectionKind::InteriorCodes
        })
    );
    // Without a bitmap, every block is stored or none.
    let mut t = tiny(BlockCode::F16);
    part(&mut t, true).codes.pop();
    assert_eq!(
        load32(&t.bytes()),
        Err(LoadError::SectionSize {
            kind: SectionKind::SurfaceCodes
        })
    );
    let mut t = tiny(BlockCode::F16);
    part(&mut t, false).codes.clear();
    let file = TableFile::from_bytes(&t.bytes());
    let table = PrecomputedTable::<f32>::load(file.bytes()).expect("every interior block dropped");
    let interior = table.interior_blocks();
    assert_eq!((interior.len(), interior.stored_len()), (4, 0));
    assert!((0..4).all(|k| !interior.is_stored(k) && interior.block(k, k) == Some([0.0; 9])));
    let mut t = tiny(BlockCode::Q16);
    part(&mut t, true).codes.clear();
    assert_eq!(
        load32(&t.bytes()),
        Err(LoadError::DroppedDiagonal { touchable: 0 })
    );
    // A diagonal block dropped: C_22 is surface block 5.
    let mut t = tiny(BlockCode::Q16);
    let surface = part(&mut t, true);
    surface.codes.remove(5);
    let mut flags = [true; 10];
    flags[5] = false;
    surface.kept = Some(kept_bitmap(&flags));
    assert_eq!(
        load32(&t.bytes()),
        Err(LoadError::DroppedDiagonal { touchable: 2 })
    );
    // An off-diagonal one dropped is fine: C_12 is block 4.
    let mut t = tiny(BlockCode::Q16);
    let surface = part(&mut t, true);
    surface.codes.remove(4);
    let mut flags = [true; 10];
    flags[4] = false;
    surface.kept = Some(kept_bitmap(&flags));
    assert_eq!(load32(&t.bytes()), Ok(()));
}

/// The rank of a word past the first, in a real table's bitmap: the firmware box compressed
/// with blocks dropped in both parts, its bytes patched and the checksum repaired.
#[test]
fn a_wrong_rank_past_the_first_word_is_refused() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mesh = root.join("tools/firmware-m4f/mesh/box.node");
    let (mesh, report) = palpate::mesh::read_mesh(&mesh).expect("box mesh");
    let mut options = palpate::table::build::BuildOptions::precomputed(
        palpate::fem::material::Material::new(3000.0, 0.45).expect("material"),
        vec!["z<0.001".parse().expect("predicate")],
        palpate::table::compliance::Solver::Cholesky,
        Precision::F32,
    );
    options.kind = palpate::table::build::TableKindOptions::Precomputed {
        solver: palpate::table::compliance::Solver::Cholesky,
        compression: Some(Compression {
            code: BlockCode::Q16,
            drop_below: 0.2,
            contact: ContactBlocks::Dropped,
            tolerance: palpate::table::hmatrix::DEFAULT_TOLERANCE,
        }),
        tool_radius_m: palpate::table::build::DEFAULT_LIST_TOOL_RADIUS_M,
    };
    let bytes = palpate::table::build::build(&mesh, &report, &options)
        .expect("build")
        .bytes;
    assert_eq!(load32(&bytes), Ok(()));
    for kind in [SectionKind::SurfaceKept, SectionKind::InteriorKept] {
        // Word 3's rank (bytes 4..8 of its 8), one too many.
        let patched = palpate_tests::patch_section(&bytes, kind, |words| {
            let rank = u32::from_le_bytes(words[28..32].try_into().unwrap());
            words[28..32].copy_from_slice(&(rank + 1).to_le_bytes());
        });
        assert_eq!(
            load32(&patched),
            Err(LoadError::BadKeptBlocks { kind, word: 3 }),
            "{kind:?}"
        );
    }
}

#[test]
fn bad_records_and_sections_of_another_encoding_are_refused() {
    let set = |f: fn(&mut CompressedCompliance)| {
        let mut t = tiny(BlockCode::Q16);
        f(t.compressed.as_mut().expect("compressed"));
        load32(&t.bytes())
    };
    for f in [
        (|c: &mut CompressedCompliance| c.record.drop_below = 1.0) as fn(&mut _),
        |c| c.record.drop_below = -0.1,
        |c| c.record.drop_below = f64::NAN,
        |c| c.record.max_force_error = -1e-3,
        |c| c.record.max_displacement_error = f64::INFINITY,
        |c| c.record.max_surface_displacement_error = f64::NAN,
        |c| c.record.reserved = 1,
    ] {
        assert_eq!(set(f), Err(LoadError::BadCompressionRecord));
    }
    assert_eq!(
        set(|c| c.record.interior_encoding = 7),
        Err(LoadError::UnknownEncoding {
            part: SectionKind::ComplianceInterior,
            found: 7
        })
    );
    // The record says the surface is in the table scalar, the table holds it coded.
    assert_eq!(
        set(|c| c.record.surface_encoding = BlockEncoding::Scalar as u32),
        Err(LoadError::UnexpectedSection {
            kind: SectionKind::SurfaceScale
        })
    );
    // The record says coded, the table holds it dense.
    assert_eq!(
        set(|c| c.surface = None),
        Err(LoadError::UnexpectedSection {
            kind: SectionKind::ComplianceSurface
        })
    );
}
