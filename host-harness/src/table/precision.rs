//! The float width a table stores its scalars in: a leaf that the writer
//! ([`super::file`]) and the collision index ([`super::collision`]) both take.

/// Float width of the stored tables: `f32` for firmware (the default), `f64`
/// for verification against reference data.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Precision {
    /// 4-byte floats.
    F32,
    /// 8-byte floats.
    F64,
}

impl Precision {
    /// Bytes of one stored scalar (the header's `scalar_bytes`).
    pub fn scalar_bytes(self) -> u32 {
        match self {
            Precision::F32 => 4,
            Precision::F64 => 8,
        }
    }
}
