//! Status codes: what every function returns. One code per way the call
//! can fail: the boundary's own (null pointers, alignment, handles,
//! arguments, memory), then one per variant of each kernel error enum, in
//! ranges by enum (100: tables, 200: contacts, 300: loop configuration,
//! 400: tensor-mass state and physics, 500: the hybrid coupling). A
//! failure's details (which contact, vertex or section) are in
//! [`crate::error::Error`].

use core::ffi::{CStr, c_char};

use palpate_kernel::haptic::LoopError;
use palpate_kernel::hybrid::{FieldError, HybridError, HybridTissueError};
use palpate_kernel::precomputed::DisplacementError;
use palpate_kernel::tensor_mass::{
    DynamicTissueError, Fault, PhysicsError, StateError, StepError, SurfaceBufferError,
};
use palpate_kernel::{ContactError, LoadError};

/// What a function did: `PALPATE_STATUS_OK`, or why it did nothing (a function
/// that fails leaves its outputs and handles as they were, except a
/// creation's handle, which is marked not initialized).
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    /// Success.
    Ok = 0,

    // The boundary's own checks.
    /// A required pointer is null.
    NullPointer = 1,
    /// A pointer is not aligned for its type (a handle: 8 bytes; `float` and
    /// `uint32_t` arrays: 4; the memory block: `PALPATE_MEMORY_ALIGN`).
    Misaligned = 2,
    /// A handle that no successful call created (never created, or its
    /// creation failed).
    NotInitialized = 3,
    /// A table handle of another kind than the function takes (a
    /// tensor-mass table where a pre-computed one is needed).
    WrongTable = 4,
    /// An argument out of range: an enum value not in its list, a count
    /// above its capacity, a tool count other than the loop's.
    BadArgument = 5,
    /// The memory block is smaller than `palpate_*_memory_size` says.
    MemoryTooSmall = 6,

    // Tables (`palpate_*_table_load`): the kernel's `LoadError`.
    /// Fewer bytes than a header and a checksum.
    TableTooShort = 100,
    /// Not a Palpate table (the first 8 bytes are not `PALPTBL\0`).
    TableBadMagic = 101,
    /// A table format version this library does not read
    /// (`PALPATE_TABLE_FORMAT_VERSION`).
    TableUnsupportedVersion = 102,
    /// The length given differs from the header's (truncated or padded).
    TableLengthMismatch = 103,
    /// The CRC-32 trailer does not match the contents: a corrupt table.
    TableChecksumMismatch = 104,
    /// The table stores f64; this library reads f32 tables
    /// (`palpate tables build --precision f32`).
    TableScalarMismatch = 105,
    /// The table is of another kind than the function loads.
    TableWrongKind = 106,
    /// The header's counts contradict each other.
    TableInconsistentHeader = 107,
    /// The header's material is out of range.
    TableBadMaterial = 108,
    /// A section kind this version does not know.
    TableUnknownSection = 109,
    /// A section occurs twice.
    TableDuplicateSection = 110,
    /// A required section is missing.
    TableMissingSection = 111,
    /// A section has the wrong size.
    TableSectionSize = 112,
    /// A section lies outside the table.
    TableSectionBounds = 113,
    /// A section is misaligned in memory: the table's bytes must start on
    /// a 16-byte boundary.
    TableMisaligned = 114,
    /// The vertex maps disagree.
    TableBadVertexMap = 115,
    /// A surface triangle references a vertex out of range.
    TableBadTriangle = 116,
    /// A non-finite value.
    TableNonFinite = 117,
    /// The edge list is broken.
    TableBadEdges = 118,
    /// A tet's references or rest volume are invalid.
    TableBadTet = 119,
    /// A mesh triangle is invalid or out of order.
    TableBadMeshTriangle = 120,
    /// A tet's mesh-triangle reference is invalid.
    TableBadTetTriangle = 121,
    /// The collision grid is malformed.
    TableBadSurfaceGrid = 122,
    /// A surface triangle's stored plane is wrong.
    TableBadSurfacePlane = 123,
    /// A vertex's surface-triangle list is malformed.
    TableBadVertexTriangles = 124,
    /// A lumped mass or vertex tensor is invalid.
    TableBadVertexData = 125,
    /// A connection node of an interface table is invalid.
    TableBadConnection = 126,
    /// A tet's Lamé coefficients are out of range.
    TableBadTetMaterial = 127,
    /// A diagonal compliance block is not symmetric positive definite.
    TableNotPositiveDefinite = 128,
    /// Compressed table: the compliance-encoding record is malformed (`LoadError::BadCompressionRecord`).
    TableBadCompressionRecord = 129,
    /// Compressed table: unknown block encoding (`LoadError::UnknownEncoding`).
    TableUnknownEncoding = 130,
    /// Table section not used by its compliance encoding (`LoadError::UnexpectedSection`).
    TableUnexpectedSection = 131,
    /// Compressed table: a column scale is not finite and > 0, or too large for the codes
    /// (`LoadError::BadScale`).
    TableBadScale = 132,
    /// Compressed table: a fixed-point code is -32768 (`LoadError::BadCode`).
    TableBadCode = 133,
    /// Compressed table: kept-block bitmap inconsistent (`LoadError::BadKeptBlocks`).
    TableBadKeptBlocks = 134,
    /// Compressed table: a diagonal compliance block was dropped (`LoadError::DroppedDiagonal`).
    TableDroppedDiagonal = 135,
    /// A tet's `tet-lanes` entry differs from its rest shape and material
    /// (`LoadError::BadTetLanes`).
    TableBadTetLanes = 136,
    /// A grid cell's candidate triangle list is not the triangles the grid
    /// files there (`LoadError::BadCellTriangles`).
    TableBadCellTriangles = 137,
    /// Hierarchical table: a hierarchy section is inconsistent
    /// (`LoadError::BadHierarchy`).
    TableBadHierarchy = 138,

    // Contacts (`palpate_precomputed_solve`, `..._displacements`): the
    // kernel's `ContactError` and `DisplacementError`.
    /// More contacts than `PALPATE_MAX_CONTACTS`.
    ContactTooMany = 200,
    /// A vertex index beyond the mesh.
    ContactVertexOutOfRange = 201,
    /// A vertex contact on a fixed vertex.
    ContactFixedVertex = 202,
    /// A vertex contact on a vertex that is not on the boundary surface.
    ContactNotOnSurface = 203,
    /// A triangle contact names a vertex twice.
    ContactRepeatedVertex = 204,
    /// A triangle contact's vertices are not a triangle of the surface.
    ContactNotSurfaceTriangle = 205,
    /// Barycentric weights outside `[0, 1]` or not summing to 1.
    ContactBadWeights = 206,
    /// A non-finite displacement or weight.
    ContactNonFiniteInput = 207,
    /// Two vertex contacts on one vertex.
    ContactDuplicate = 208,
    /// The contact system is singular or ill-conditioned.
    ContactIllConditioned = 209,
    /// The solve produced a non-finite force.
    ContactNonFiniteResult = 210,
    /// A displacement buffer does not hold one entry per vertex.
    DisplacementBuffer = 211,

    // Loop configuration (`palpate_*_loop_create`): the kernel's `LoopError`.
    /// Tool radius or haptic period not finite and positive.
    LoopBadConfig = 300,
    /// Safety limits (force, slew) not finite and positive.
    LoopBadLimits = 301,

    // The tensor-mass model (`palpate_dynamic_*`, `palpate_hybrid_*`):
    // `StateError`, `DynamicTissueError`, `PhysicsError`, `StepError`,
    // `Fault`.
    /// A state buffer has the wrong length.
    StateBufferLength = 400,
    /// A physics parameter (damping, gravity, bounds, penalty) out of range.
    StateBadParameter = 401,
    /// The split St Venant-Kirchhoff form without its buffers.
    StateNoTermBuffers = 402,
    /// A surface buffer has the wrong length.
    SurfaceBufferLength = 410,
    /// The force scratch buffer has the wrong length.
    ForceBufferLength = 411,
    /// Physics step, sub-steps, removal capacities or cut force out of
    /// range.
    BadPhysics = 412,
    /// The model diverged: a non-finite state (a latched fault: reset).
    FaultNonFinite = 420,
    /// The model diverged: a displacement beyond the bound (reset).
    FaultDisplacementBound = 421,
    /// The model diverged: kinetic energy beyond the bound (reset).
    FaultKineticEnergyBound = 422,
    /// The physics step is not finite and positive.
    StepBadTimeStep = 423,
    /// RK4 without its scratch buffers.
    StepNoRk4Scratch = 424,
    /// The deformed surface has a non-finite vertex (reset).
    SurfaceNonFinite = 425,
    /// A contact's imposed displacement is not finite (reset).
    ContactNonFiniteDisplacement = 426,

    // The hybrid coupling (`palpate_hybrid_*`): `HybridError`.
    /// A coupling buffer has the wrong length.
    HybridBufferLength = 500,
    /// The three tables do not belong together (another build, mesh,
    /// partition or material).
    HybridMismatch = 501,
}

impl Status {
    /// A short description of the code (the detailed message of a failure:
    /// `palpate_error_message`).
    pub fn message(self) -> &'static CStr {
        match self {
            Self::Ok => c"ok",
            Self::NullPointer => c"a required pointer is null",
            Self::Misaligned => c"a pointer is not aligned for its type",
            Self::NotInitialized => c"the handle was not created by a successful call",
            Self::WrongTable => c"the table handle is of another kind than the function takes",
            Self::BadArgument => c"an argument is out of range",
            Self::MemoryTooSmall => c"the memory block is too small",
            Self::TableTooShort => c"table too short",
            Self::TableBadMagic => c"not a Palpate table (bad magic)",
            Self::TableUnsupportedVersion => c"table format version not read by this library",
            Self::TableLengthMismatch => c"table length differs from its header (truncated?)",
            Self::TableChecksumMismatch => c"table checksum mismatch (corrupt table)",
            Self::TableScalarMismatch => c"table stores another float width than f32",
            Self::TableWrongKind => c"table of another kind",
            Self::TableInconsistentHeader => c"inconsistent table header counts",
            Self::TableBadMaterial => c"material out of range in the table header",
            Self::TableUnknownSection => c"unknown table section",
            Self::TableDuplicateSection => c"table section occurs twice",
            Self::TableMissingSection => c"table section missing",
            Self::TableSectionSize => c"table section has the wrong size",
            Self::TableSectionBounds => c"table section lies outside the table",
            Self::TableMisaligned => c"table misaligned in memory (align it to 16 bytes)",
            Self::TableBadVertexMap => c"table vertex maps disagree",
            Self::TableBadTriangle => c"table surface triangle out of range",
            Self::TableNonFinite => c"non-finite value in the table",
            Self::TableBadEdges => c"table edge list broken",
            Self::TableBadTet => c"invalid tet in the table",
            Self::TableBadMeshTriangle => c"invalid mesh triangle in the table",
            Self::TableBadTetTriangle => c"invalid tet triangle reference in the table",
            Self::TableBadSurfaceGrid => c"table collision grid malformed",
            Self::TableBadSurfacePlane => c"table surface plane wrong",
            Self::TableBadVertexTriangles => c"table vertex triangle list malformed",
            Self::TableBadVertexData => c"invalid mass or vertex tensor in the table",
            Self::TableBadConnection => c"invalid connection node in the interface table",
            Self::TableBadTetMaterial => c"tet material out of range in the table",
            Self::TableNotPositiveDefinite => c"table compliance block not positive definite",
            Self::TableBadCompressionRecord => {
                c"compressed table: the compliance-encoding record is malformed"
            }
            Self::TableUnknownEncoding => c"compressed table: unknown block encoding",
            Self::TableUnexpectedSection => c"table section not used by its compliance encoding",
            Self::TableBadScale => c"compressed table: a column scale is not finite and > 0, or too large for the codes",
            Self::TableBadCode => c"compressed table: a fixed-point code is -32768",
            Self::TableBadKeptBlocks => c"compressed table: kept-block bitmap inconsistent",
            Self::TableBadHierarchy => c"hierarchical table: a hierarchy section is inconsistent",
            Self::TableDroppedDiagonal => {
                c"compressed table: a diagonal compliance block was dropped"
            }
            Self::TableBadTetLanes => {
                c"table tet-lanes entry differs from the tet's shape or material"
            }
            Self::TableBadCellTriangles => {
                c"table grid cell's candidate triangle list is not the triangles filed there"
            }
            Self::ContactTooMany => c"more contacts than PALPATE_MAX_CONTACTS",
            Self::ContactVertexOutOfRange => c"contact vertex out of range",
            Self::ContactFixedVertex => c"contact on a fixed vertex",
            Self::ContactNotOnSurface => c"contact vertex not on the boundary surface",
            Self::ContactRepeatedVertex => c"triangle contact repeats a vertex",
            Self::ContactNotSurfaceTriangle => c"contact vertices are not a surface triangle",
            Self::ContactBadWeights => c"barycentric weights not in [0, 1] or not summing to 1",
            Self::ContactNonFiniteInput => c"non-finite contact displacement or weight",
            Self::ContactDuplicate => c"two contacts on the same vertex",
            Self::ContactIllConditioned => c"contact system singular or ill-conditioned",
            Self::ContactNonFiniteResult => c"contact solve produced a non-finite force",
            Self::DisplacementBuffer => c"displacement buffer length is not the vertex count",
            Self::LoopBadConfig => c"tool radius and haptic period must be finite and > 0",
            Self::LoopBadLimits => c"safety limits must be finite and > 0",
            Self::StateBufferLength => c"tensor-mass state buffer of the wrong length",
            Self::StateBadParameter => c"physics parameter out of range",
            Self::StateNoTermBuffers => c"split St Venant-Kirchhoff form without its buffers",
            Self::SurfaceBufferLength => c"surface buffer of the wrong length",
            Self::ForceBufferLength => c"force buffer of the wrong length",
            Self::BadPhysics => c"physics step, sub-steps, capacities or cut force out of range",
            Self::FaultNonFinite => c"model fault: non-finite state",
            Self::FaultDisplacementBound => c"model fault: displacement beyond the bound",
            Self::FaultKineticEnergyBound => c"model fault: kinetic energy beyond the bound",
            Self::StepBadTimeStep => c"physics step must be finite and > 0 s",
            Self::StepNoRk4Scratch => c"RK4 without its scratch buffers",
            Self::SurfaceNonFinite => c"deformed surface has a non-finite vertex",
            Self::ContactNonFiniteDisplacement => c"non-finite contact displacement",
            Self::HybridBufferLength => c"hybrid coupling buffer of the wrong length",
            Self::HybridMismatch => c"the three hybrid tables do not belong together",
        }
    }
}

impl From<LoadError> for Status {
    fn from(e: LoadError) -> Self {
        match e {
            LoadError::TooShort { .. } => Self::TableTooShort,
            LoadError::BadMagic => Self::TableBadMagic,
            LoadError::UnsupportedVersion { .. } => Self::TableUnsupportedVersion,
            LoadError::LengthMismatch { .. } => Self::TableLengthMismatch,
            LoadError::ChecksumMismatch { .. } => Self::TableChecksumMismatch,
            LoadError::ScalarMismatch { .. } => Self::TableScalarMismatch,
            LoadError::WrongTableKind { .. } => Self::TableWrongKind,
            LoadError::InconsistentHeader => Self::TableInconsistentHeader,
            LoadError::BadMaterial => Self::TableBadMaterial,
            LoadError::UnknownSection { .. } => Self::TableUnknownSection,
            LoadError::DuplicateSection { .. } => Self::TableDuplicateSection,
            LoadError::MissingSection { .. } => Self::TableMissingSection,
            LoadError::SectionSize { .. } => Self::TableSectionSize,
            LoadError::SectionBounds { .. } => Self::TableSectionBounds,
            LoadError::Misaligned { .. } => Self::TableMisaligned,
            LoadError::BadVertexMap { .. } => Self::TableBadVertexMap,
            LoadError::BadTriangle { .. } => Self::TableBadTriangle,
            LoadError::NonFinite { .. } => Self::TableNonFinite,
            LoadError::BadEdges { .. } => Self::TableBadEdges,
            LoadError::BadTet { .. } => Self::TableBadTet,
            LoadError::BadMeshTriangle { .. } => Self::TableBadMeshTriangle,
            LoadError::BadTetTriangle { .. } => Self::TableBadTetTriangle,
            LoadError::BadSurfaceGrid { .. } => Self::TableBadSurfaceGrid,
            LoadError::BadSurfacePlane { .. } => Self::TableBadSurfacePlane,
            LoadError::BadVertexTriangles { .. } => Self::TableBadVertexTriangles,
            LoadError::BadVertexData { .. } => Self::TableBadVertexData,
            LoadError::BadConnection { .. } => Self::TableBadConnection,
            LoadError::BadTetMaterial { .. } => Self::TableBadTetMaterial,
            LoadError::NotPositiveDefinite { .. } => Self::TableNotPositiveDefinite,
            LoadError::BadCompressionRecord => Self::TableBadCompressionRecord,
            LoadError::UnknownEncoding { .. } => Self::TableUnknownEncoding,
            LoadError::UnexpectedSection { .. } => Self::TableUnexpectedSection,
            LoadError::BadScale { .. } => Self::TableBadScale,
            LoadError::BadCode { .. } => Self::TableBadCode,
            LoadError::BadKeptBlocks { .. } => Self::TableBadKeptBlocks,
            LoadError::BadHierarchy { .. } => Self::TableBadHierarchy,
            LoadError::DroppedDiagonal { .. } => Self::TableDroppedDiagonal,
            LoadError::BadTetLanes { .. } => Self::TableBadTetLanes,
            LoadError::BadCellTriangles { .. } => Self::TableBadCellTriangles,
        }
    }
}

impl From<ContactError> for Status {
    fn from(e: ContactError) -> Self {
        match e {
            ContactError::TooManyContacts { .. } => Self::ContactTooMany,
            ContactError::VertexOutOfRange { .. } => Self::ContactVertexOutOfRange,
            ContactError::FixedVertex { .. } => Self::ContactFixedVertex,
            ContactError::NotOnSurface { .. } => Self::ContactNotOnSurface,
            ContactError::RepeatedVertex { .. } => Self::ContactRepeatedVertex,
            ContactError::NotSurfaceTriangle { .. } => Self::ContactNotSurfaceTriangle,
            ContactError::BadWeights { .. } => Self::ContactBadWeights,
            ContactError::NonFiniteInput { .. } => Self::ContactNonFiniteInput,
            ContactError::DuplicateContact { .. } => Self::ContactDuplicate,
            ContactError::IllConditioned { .. } => Self::ContactIllConditioned,
            ContactError::NonFiniteResult => Self::ContactNonFiniteResult,
        }
    }
}

impl From<DisplacementError> for Status {
    fn from(_: DisplacementError) -> Self {
        Self::DisplacementBuffer
    }
}

impl From<LoopError> for Status {
    fn from(e: LoopError) -> Self {
        match e {
            LoopError::BadConfig => Self::LoopBadConfig,
            LoopError::BadLimits(_) => Self::LoopBadLimits,
        }
    }
}

impl From<StateError> for Status {
    fn from(e: StateError) -> Self {
        match e {
            StateError::BufferLength { .. } => Self::StateBufferLength,
            StateError::BadParameter { .. } => Self::StateBadParameter,
            StateError::NoTermBuffers => Self::StateNoTermBuffers,
        }
    }
}

impl From<SurfaceBufferError> for Status {
    fn from(_: SurfaceBufferError) -> Self {
        Self::SurfaceBufferLength
    }
}

impl From<DynamicTissueError> for Status {
    fn from(e: DynamicTissueError) -> Self {
        match e {
            DynamicTissueError::Surface(e) => e.into(),
            DynamicTissueError::ForceBuffer { .. } => Self::ForceBufferLength,
            DynamicTissueError::BadPhysics => Self::BadPhysics,
        }
    }
}

impl From<Fault> for Status {
    fn from(e: Fault) -> Self {
        match e {
            Fault::NonFinite { .. } => Self::FaultNonFinite,
            Fault::DisplacementBound { .. } => Self::FaultDisplacementBound,
            Fault::KineticEnergyBound => Self::FaultKineticEnergyBound,
        }
    }
}

impl From<StepError> for Status {
    fn from(e: StepError) -> Self {
        match e {
            StepError::Faulted(fault) => fault.into(),
            StepError::BadTimeStep => Self::StepBadTimeStep,
            StepError::NoRk4Scratch => Self::StepNoRk4Scratch,
        }
    }
}

impl From<PhysicsError> for Status {
    fn from(e: PhysicsError) -> Self {
        match e {
            PhysicsError::Step(e) => e.into(),
            PhysicsError::Surface(_) => Self::SurfaceNonFinite,
            PhysicsError::NonFiniteContact { .. } => Self::ContactNonFiniteDisplacement,
        }
    }
}

impl From<HybridError> for Status {
    fn from(e: HybridError) -> Self {
        match e {
            HybridError::Buffer { .. } => Self::HybridBufferLength,
            HybridError::Mismatch { .. } => Self::HybridMismatch,
        }
    }
}

impl From<HybridTissueError> for Status {
    fn from(e: HybridTissueError) -> Self {
        match e {
            HybridTissueError::Coupling(e) => e.into(),
            HybridTissueError::Dynamic(e) => e.into(),
            HybridTissueError::Surface(e) => e.into(),
        }
    }
}

impl From<FieldError> for Status {
    fn from(e: FieldError) -> Self {
        match e {
            FieldError::Length(e) => e.into(),
            FieldError::Faulted(fault) => fault.into(),
        }
    }
}

/// Every status code, in ascending order (for `palpate_status_message` of a
/// raw number, and the tests).
///
/// cbindgen:ignore
pub const ALL: [Status; 75] = [
    Status::Ok,
    Status::NullPointer,
    Status::Misaligned,
    Status::NotInitialized,
    Status::WrongTable,
    Status::BadArgument,
    Status::MemoryTooSmall,
    Status::TableTooShort,
    Status::TableBadMagic,
    Status::TableUnsupportedVersion,
    Status::TableLengthMismatch,
    Status::TableChecksumMismatch,
    Status::TableScalarMismatch,
    Status::TableWrongKind,
    Status::TableInconsistentHeader,
    Status::TableBadMaterial,
    Status::TableUnknownSection,
    Status::TableDuplicateSection,
    Status::TableMissingSection,
    Status::TableSectionSize,
    Status::TableSectionBounds,
    Status::TableMisaligned,
    Status::TableBadVertexMap,
    Status::TableBadTriangle,
    Status::TableNonFinite,
    Status::TableBadEdges,
    Status::TableBadTet,
    Status::TableBadMeshTriangle,
    Status::TableBadTetTriangle,
    Status::TableBadSurfaceGrid,
    Status::TableBadSurfacePlane,
    Status::TableBadVertexTriangles,
    Status::TableBadVertexData,
    Status::TableBadConnection,
    Status::TableBadTetMaterial,
    Status::TableNotPositiveDefinite,
    Status::TableBadCompressionRecord,
    Status::TableUnknownEncoding,
    Status::TableUnexpectedSection,
    Status::TableBadScale,
    Status::TableBadCode,
    Status::TableBadKeptBlocks,
    Status::TableDroppedDiagonal,
    Status::TableBadTetLanes,
    Status::TableBadCellTriangles,
    Status::TableBadHierarchy,
    Status::ContactTooMany,
    Status::ContactVertexOutOfRange,
    Status::ContactFixedVertex,
    Status::ContactNotOnSurface,
    Status::ContactRepeatedVertex,
    Status::ContactNotSurfaceTriangle,
    Status::ContactBadWeights,
    Status::ContactNonFiniteInput,
    Status::ContactDuplicate,
    Status::ContactIllConditioned,
    Status::ContactNonFiniteResult,
    Status::DisplacementBuffer,
    Status::LoopBadConfig,
    Status::LoopBadLimits,
    Status::StateBufferLength,
    Status::StateBadParameter,
    Status::StateNoTermBuffers,
    Status::SurfaceBufferLength,
    Status::ForceBufferLength,
    Status::BadPhysics,
    Status::FaultNonFinite,
    Status::FaultDisplacementBound,
    Status::FaultKineticEnergyBound,
    Status::StepBadTimeStep,
    Status::StepNoRk4Scratch,
    Status::SurfaceNonFinite,
    Status::ContactNonFiniteDisplacement,
    Status::HybridBufferLength,
    Status::HybridMismatch,
];

/// A short, static, NUL-terminated description of status code `status`
/// ("unknown status code" for a number that is no code). Never null.
#[unsafe(no_mangle)]
pub extern "C" fn palpate_status_message(status: u32) -> *const c_char {
    ALL.iter()
        .find(|s| **s as u32 == status)
        .map_or(c"unknown status code", |s| s.message())
        .as_ptr()
}
