//! Shared by the integration tests (and, later, golden renders and
//! benchmarks): fixture scenes and independently derived distances.
#![allow(dead_code)]

pub mod analytic;
pub mod fixtures;
pub mod profiles;
pub mod shapes;
