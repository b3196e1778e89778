//! Failure details (`ffi/src/error.rs`): `palpate_error_message` writes the
//! kernel's own message (its `Display`, what the host prints), truncated
//! to the buffer as `snprintf` does.

use palpate_ffi::error::{Detail, Error, palpate_error_message};
use palpate_ffi::status::Status;
use palpate_ffi::table::{Table, palpate_precomputed_table_load};
use palpate_kernel::{ContactError, LoadError};

/// The message of `error` through a buffer of `capacity` bytes: the
/// returned length, and the bytes before the NUL.
fn message(error: &Error, capacity: usize) -> (usize, Vec<u8>) {
    let mut buffer = vec![0xAAu8; capacity];
    // SAFETY: `error` is a live (or zeroed) handle; `buffer` holds `capacity`
    // writable bytes (a NULL pointer when 0 is allowed, a dangling one too:
    // nothing is written).
    let len = unsafe { palpate_error_message(error, buffer.as_mut_ptr().cast(), capacity) };
    let end = buffer.iter().position(|&b| b == 0).unwrap_or(capacity);
    if capacity > 0 {
        assert!(end < capacity, "no NUL in the buffer");
        assert!(
            buffer[end + 1..].iter().all(|&b| b == 0xAA),
            "wrote past the NUL"
        );
    }
    buffer.truncate(end);
    (len, buffer)
}

#[test]
fn messages_are_the_kernels_truncated_to_fit() {
    // A failed load records the kernel's LoadError.
    let mut table = Table::default();
    let mut error = Error::default();
    let bytes = [0u8; 10];
    // SAFETY: live handle and error; 10 readable bytes.
    let status =
        unsafe { palpate_precomputed_table_load(&mut table, bytes.as_ptr(), 10, &mut error) };
    assert_eq!(status, Status::TableTooShort);
    let expected = LoadError::TooShort { len: 10 }.to_string();
    assert_eq!(expected, "table too short (10 bytes)");
    let (len, text) = message(&error, 256);
    assert_eq!(
        (len, text.as_slice()),
        (expected.len(), expected.as_bytes())
    );
    // Truncated: what fits before the NUL, the full length returned.
    for capacity in [1, 2, 8, expected.len(), expected.len() + 1] {
        let (len, text) = message(&error, capacity);
        assert_eq!(len, expected.len());
        let kept = expected.len().min(capacity - 1);
        assert_eq!(
            text.as_slice(),
            &expected.as_bytes()[..kept],
            "capacity {capacity}"
        );
    }
    // Capacity 0: the length only, nothing written.
    // SAFETY: capacity 0: the buffer is not touched.
    let len = unsafe { palpate_error_message(&error, core::ptr::null_mut(), 0) };
    assert_eq!(len, expected.len());
}

#[test]
fn an_error_never_written_is_empty() {
    let error = Error::default();
    assert_eq!(message(&error, 16), (0, Vec::new()));
    // SAFETY: a null error is allowed.
    let len = unsafe { palpate_error_message(core::ptr::null(), core::ptr::null_mut(), 0) };
    assert_eq!(len, 0);
}

#[test]
fn details_display_as_the_kernel() {
    let cases = [
        (
            Detail::Contact(ContactError::FixedVertex {
                contact: 1,
                vertex: 0,
            }),
            "contact 1: vertex 0 is fixed",
        ),
        (
            Detail::Load(LoadError::UnsupportedVersion { found: 2 }),
            "table format version 2 is not read by this kernel (version 6)",
        ),
        (
            Detail::Abi(Status::NullPointer),
            "a required pointer is null",
        ),
    ];
    for (detail, text) in cases {
        assert_eq!(detail.to_string(), text);
    }
}
