//! The study's progress, reported by every part of it.

/// The study's progress: one tick per run, and a message.
pub trait Progress {
    /// One run done.
    fn tick(&mut self, message: &str);
}

impl<F: FnMut(&str)> Progress for F {
    fn tick(&mut self, message: &str) {
        self(message);
    }
}
