//! Arrays of exactly three numbers in a scene file: `[x, y, z]` with a fourth (or a second
//! missing) is an error naming the key (the parser's message shows its line), never truncated.

use serde::de::{Deserialize, Deserializer, Error};

/// A `[a, b, c]` array: three elements, no more, no fewer.
pub(crate) fn three<'de, D, T>(deserializer: D) -> Result<[T; 3], D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    let items = Vec::<T>::deserialize(deserializer)?;
    let len = items.len();
    <[T; 3]>::try_from(items)
        .map_err(|_| D::Error::invalid_length(len, &"exactly 3 numbers, [x, y, z]"))
}

/// [`three`] of an optional key (with `#[serde(default)]`).
pub(crate) fn three_opt<'de, D, T>(deserializer: D) -> Result<Option<[T; 3]>, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    three(deserializer).map(Some)
}
