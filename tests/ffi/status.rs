//! Status codes (`ffi/src/status.rs`): every variant of every kernel error
//! enum the C ABI can return has its own code, in its enum's range; the
//! codes, their messages and the generated header agree.

use palpate_ffi::error::Detail;
use palpate_ffi::status::{ALL, Status, palpate_status_message};
use palpate_kernel::haptic::{BadLimits, LoopError};
use palpate_kernel::hybrid::{FieldError, HybridError, HybridTissueError};
use palpate_kernel::precomputed::DisplacementError;
use palpate_kernel::table::format::SectionKind;
use palpate_kernel::tensor_mass::{
    DynamicTissueError, Fault, NonFinitePosition, PhysicsError, StateError, StepError,
    SurfaceBufferError,
};
use palpate_kernel::{ContactError, LoadError};

/// Every `LoadError` variant and its code.
fn load_errors() -> Vec<(LoadError, Status)> {
    let kind = SectionKind::VertexSlot;
    vec![
        (LoadError::TooShort { len: 3 }, Status::TableTooShort),
        (LoadError::BadMagic, Status::TableBadMagic),
        (
            LoadError::UnsupportedVersion { found: 2 },
            Status::TableUnsupportedVersion,
        ),
        (
            LoadError::LengthMismatch {
                declared: 10,
                actual: 9,
            },
            Status::TableLengthMismatch,
        ),
        (
            LoadError::ChecksumMismatch {
                stored: 1,
                computed: 2,
            },
            Status::TableChecksumMismatch,
        ),
        (
            LoadError::ScalarMismatch {
                table: 8,
                requested: 4,
            },
            Status::TableScalarMismatch,
        ),
        (
            LoadError::WrongTableKind { found: 2 },
            Status::TableWrongKind,
        ),
        (
            LoadError::InconsistentHeader,
            Status::TableInconsistentHeader,
        ),
        (LoadError::BadMaterial, Status::TableBadMaterial),
        (
            LoadError::UnknownSection { kind: 99 },
            Status::TableUnknownSection,
        ),
        (
            LoadError::DuplicateSection { kind },
            Status::TableDuplicateSection,
        ),
        (
            LoadError::MissingSection { kind },
            Status::TableMissingSection,
        ),
        (LoadError::SectionSize { kind }, Status::TableSectionSize),
        (
            LoadError::SectionBounds { kind },
            Status::TableSectionBounds,
        ),
        (LoadError::Misaligned { kind }, Status::TableMisaligned),
        (
            LoadError::BadVertexMap { vertex: 1 },
            Status::TableBadVertexMap,
        ),
        (
            LoadError::BadTriangle { triangle: 1 },
            Status::TableBadTriangle,
        ),
        (
            LoadError::NonFinite { kind, index: 1 },
            Status::TableNonFinite,
        ),
        (LoadError::BadEdges { vertex: 1 }, Status::TableBadEdges),
        (LoadError::BadTet { tet: 1 }, Status::TableBadTet),
        (
            LoadError::BadMeshTriangle { triangle: 1 },
            Status::TableBadMeshTriangle,
        ),
        (
            LoadError::BadTetTriangle { tet: 1 },
            Status::TableBadTetTriangle,
        ),
        (
            LoadError::BadSurfaceGrid { index: 1 },
            Status::TableBadSurfaceGrid,
        ),
        (
            LoadError::BadSurfacePlane { triangle: 1 },
            Status::TableBadSurfacePlane,
        ),
        (
            LoadError::BadVertexTriangles { vertex: 1 },
            Status::TableBadVertexTriangles,
        ),
        (
            LoadError::BadVertexData { vertex: 1 },
            Status::TableBadVertexData,
        ),
        (
            LoadError::BadConnection { connection: 1 },
            Status::TableBadConnection,
        ),
        (
            LoadError::BadTetMaterial { tet: 1 },
            Status::TableBadTetMaterial,
        ),
        (LoadError::BadTetLanes { tet: 1 }, Status::TableBadTetLanes),
        (
            LoadError::BadCellTriangles { cell: 3 },
            Status::TableBadCellTriangles,
        ),
        (
            LoadError::NotPositiveDefinite { touchable: 1 },
            Status::TableNotPositiveDefinite,
        ),
    ]
}

/// Every `ContactError` variant (and the displacement buffer's error) and
/// its code.
fn contact_errors() -> Vec<(Detail, Status)> {
    let contact = |e: ContactError, s| (Detail::Contact(e), s);
    vec![
        contact(
            ContactError::TooManyContacts {
                given: 5,
                capacity: 4,
            },
            Status::ContactTooMany,
        ),
        contact(
            ContactError::VertexOutOfRange {
                contact: 0,
                vertex: 64,
            },
            Status::ContactVertexOutOfRange,
        ),
        contact(
            ContactError::FixedVertex {
                contact: 0,
                vertex: 0,
            },
            Status::ContactFixedVertex,
        ),
        contact(
            ContactError::NotOnSurface {
                contact: 0,
                vertex: 21,
            },
            Status::ContactNotOnSurface,
        ),
        contact(
            ContactError::RepeatedVertex {
                contact: 0,
                vertex: 1,
            },
            Status::ContactRepeatedVertex,
        ),
        contact(
            ContactError::NotSurfaceTriangle {
                contact: 0,
                vertices: [1, 2, 3],
            },
            Status::ContactNotSurfaceTriangle,
        ),
        contact(
            ContactError::BadWeights { contact: 0 },
            Status::ContactBadWeights,
        ),
        contact(
            ContactError::NonFiniteInput { contact: 0 },
            Status::ContactNonFiniteInput,
        ),
        contact(
            ContactError::DuplicateContact {
                first: 0,
                second: 1,
            },
            Status::ContactDuplicate,
        ),
        contact(
            ContactError::IllConditioned { contact: 0 },
            Status::ContactIllConditioned,
        ),
        contact(
            ContactError::NonFiniteResult,
            Status::ContactNonFiniteResult,
        ),
        (
            Detail::Displacement(DisplacementError {
                expected: 64,
                found: 3,
            }),
            Status::DisplacementBuffer,
        ),
    ]
}

/// The loop's, the tensor-mass model's and the hybrid's errors, each
/// variant (the nested ones with each inner variant's code).
fn model_errors() -> Vec<(Detail, Status)> {
    let surface = SurfaceBufferError {
        buffer: "planes",
        expected: 2,
        found: 1,
    };
    let faults = [
        (Fault::NonFinite { vertex: 3 }, Status::FaultNonFinite),
        (
            Fault::DisplacementBound { vertex: 3 },
            Status::FaultDisplacementBound,
        ),
        (Fault::KineticEnergyBound, Status::FaultKineticEnergyBound),
    ];
    let mut cases = vec![
        (Detail::Loop(LoopError::BadConfig), Status::LoopBadConfig),
        (
            Detail::Loop(LoopError::BadLimits(BadLimits)),
            Status::LoopBadLimits,
        ),
        (
            Detail::State(StateError::BufferLength {
                buffer: "masses_kg",
                expected: 2,
                found: 1,
            }),
            Status::StateBufferLength,
        ),
        (
            Detail::State(StateError::BadParameter {
                name: "damping_per_s",
            }),
            Status::StateBadParameter,
        ),
        (
            Detail::State(StateError::NoTermBuffers),
            Status::StateNoTermBuffers,
        ),
        (
            Detail::DynamicTissue(DynamicTissueError::Surface(surface)),
            Status::SurfaceBufferLength,
        ),
        (
            Detail::DynamicTissue(DynamicTissueError::ForceBuffer {
                expected: 2,
                found: 1,
            }),
            Status::ForceBufferLength,
        ),
        (
            Detail::DynamicTissue(DynamicTissueError::BadPhysics),
            Status::BadPhysics,
        ),
        (
            Detail::Physics(PhysicsError::Step(StepError::BadTimeStep)),
            Status::StepBadTimeStep,
        ),
        (
            Detail::Physics(PhysicsError::Step(StepError::NoRk4Scratch)),
            Status::StepNoRk4Scratch,
        ),
        (
            Detail::Physics(PhysicsError::Surface(NonFinitePosition { vertex: 1 })),
            Status::SurfaceNonFinite,
        ),
        (
            Detail::Physics(PhysicsError::NonFiniteContact { tool: 0 }),
            Status::ContactNonFiniteDisplacement,
        ),
        (
            Detail::Hybrid(HybridError::Buffer {
                name: "background_m",
                expected: 2,
                found: 1,
            }),
            Status::HybridBufferLength,
        ),
        (
            Detail::Hybrid(HybridError::Mismatch {
                what: "checksums differ",
                vertex: None,
            }),
            Status::HybridMismatch,
        ),
        (
            Detail::HybridTissue(HybridTissueError::Coupling(HybridError::Mismatch {
                what: "checksums differ",
                vertex: Some(3),
            })),
            Status::HybridMismatch,
        ),
        (
            Detail::HybridTissue(HybridTissueError::Dynamic(DynamicTissueError::BadPhysics)),
            Status::BadPhysics,
        ),
        (
            Detail::HybridTissue(HybridTissueError::Surface(surface)),
            Status::SurfaceBufferLength,
        ),
        (
            Detail::Field(FieldError::Length(DisplacementError {
                expected: 64,
                found: 1,
            })),
            Status::DisplacementBuffer,
        ),
    ];
    for (fault, status) in faults {
        cases.push((Detail::Fault(fault), status));
        cases.push((
            Detail::Physics(PhysicsError::Step(StepError::Faulted(fault))),
            status,
        ));
        cases.push((Detail::Field(FieldError::Faulted(fault)), status));
    }
    cases
}

#[test]
fn every_kernel_error_has_its_code() {
    let loads = load_errors();
    // 31 LoadError variants, each its own code in the table range.
    assert_eq!(loads.len(), 31);
    for (e, status) in &loads {
        assert_eq!(Status::from(*e), *status, "{e:?}");
        assert_eq!(Detail::Load(*e).status(), *status);
        assert!((100..200).contains(&(*status as u32)), "{status:?}");
    }
    let mut codes: Vec<u32> = loads.iter().map(|(_, s)| *s as u32).collect();
    codes.dedup();
    assert_eq!(codes.len(), loads.len(), "a code shared by two load errors");

    let contacts = contact_errors();
    for (detail, status) in &contacts {
        assert_eq!(detail.status(), *status, "{detail:?}");
        assert!((200..300).contains(&(*status as u32)), "{status:?}");
    }
    let mut codes: Vec<u32> = contacts.iter().map(|(_, s)| *s as u32).collect();
    codes.sort_unstable();
    codes.dedup();
    assert_eq!(codes.len(), contacts.len());

    for (detail, status) in model_errors() {
        assert_eq!(detail.status(), status, "{detail:?}");
        let range = match detail {
            Detail::Loop(_) => 300..400,
            Detail::Hybrid(_) => 500..600,
            Detail::HybridTissue(HybridTissueError::Coupling(_)) => 500..600,
            Detail::Field(FieldError::Length(_)) => 200..300,
            _ => 400..500,
        };
        assert!(range.contains(&(status as u32)), "{detail:?}: {status:?}");
    }
    // The boundary's own codes are below 100.
    for s in [
        Status::NullPointer,
        Status::Misaligned,
        Status::NotInitialized,
        Status::WrongTable,
        Status::BadArgument,
        Status::MemoryTooSmall,
    ] {
        assert_eq!(Detail::Abi(s).status(), s);
        assert!((1..100).contains(&(s as u32)));
    }
}

/// The value and name of each `PALPATE_STATUS_*` of the header's enum.
fn header_codes() -> Vec<(String, u32)> {
    let header = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../ffi/include/palpate.h"),
    )
    .expect("ffi/include/palpate.h");
    header
        .lines()
        .filter_map(|line| {
            let (name, value) = line.trim().strip_suffix(',')?.split_once(" = ")?;
            let name = name.strip_prefix("PALPATE_STATUS_")?;
            Some((name.to_string(), value.parse().ok()?))
        })
        .collect()
}

#[test]
fn codes_messages_and_the_header_agree() {
    // ALL is every code, ascending: the header's enum (generated from the
    // Rust enum by cbindgen) has exactly these values.
    let header = header_codes();
    let values: Vec<u32> = ALL.iter().map(|s| *s as u32).collect();
    assert_eq!(
        header.iter().map(|(_, v)| *v).collect::<Vec<_>>(),
        values,
        "ALL and the header's palpate_status differ"
    );
    assert!(values.windows(2).all(|w| w[0] < w[1]));
    assert_eq!(
        header.first().map(|(n, v)| (n.as_str(), *v)),
        Some(("OK", 0))
    );
    // Each code's message: its own, non-empty, and what palpate_status_message
    // returns for the number.
    let mut messages: Vec<&str> = Vec::new();
    for s in ALL {
        let m = s.message().to_str().expect("ASCII");
        assert!(!m.is_empty());
        assert!(!messages.contains(&m), "{s:?} shares its message");
        messages.push(m);
        // SAFETY: palpate_status_message returns a static NUL-terminated string.
        let c = unsafe { core::ffi::CStr::from_ptr(palpate_status_message(s as u32)) };
        assert_eq!(c.to_str(), Ok(m));
    }
    for unknown in [7u32, 99, 139, 212, 302, 427, 502, u32::MAX] {
        // SAFETY: as above.
        let c = unsafe { core::ffi::CStr::from_ptr(palpate_status_message(unknown)) };
        assert_eq!(c.to_str(), Ok("unknown status code"), "{unknown}");
    }
}
