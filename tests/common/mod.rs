//! Set-up shared by the tests: the program run as a user runs it, a
//! Chromium for the page tests,
//! closed-form slab references, a reader of the JSON fixtures, a packed layer
//! of one pigment, runs on a thread pool of a given size, and builders of
//! scene and study files (a test names only what it varies).
#![allow(dead_code)]

pub mod airy;
pub mod browser;
pub mod cli;
pub mod json;
pub mod keys;
pub mod layers;
pub mod scene;
pub mod study;
pub mod threads;
