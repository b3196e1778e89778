//! Palpate kernel.
#![no_std]
