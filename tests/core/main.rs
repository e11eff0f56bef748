//! Integration tests of the core: form factors and radiosity against exact answers, energy balance,
//! the Cornell box, and input errors. One test binary (modules below) keeps link time down.

mod coarsening;
mod cornell;
mod energy;
mod formfactor;
mod furnace;
mod scene_errors;
mod support;
