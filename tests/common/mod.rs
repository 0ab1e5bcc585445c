//! Set-up shared by the tests: closed-form slab references, a packed layer
//! of one pigment, and runs on a thread pool of a given size.
#![allow(dead_code)]

pub mod airy;
pub mod layers;
pub mod threads;
