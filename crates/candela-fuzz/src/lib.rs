//! candela-fuzz: a structure-aware mutation fuzzer for candela's inputs.
//!
//! cargo-fuzz needs a nightly compiler; this harness runs on stable and
//! treats `candela` as a black box. It mutates the bundled scenes in
//! `scenes/` and the meshes they use (`mutate`, over the token pieces of
//! `tokens`), runs each case as `candela render CASE.pbrt --spp 1
//! --cropwindow ...` in a child process under a memory and a time limit
//! (`run`), and classifies the outcome as ok, clean error, panic, abort,
//! hang or memory limit (`campaign` counts them and saves every case that
//! needs a look, with a replay script).
//!
//! Layout: `rng` (SplitMix64, one stream per case), `corpus` (seeds),
//! `tokens`, `mutate` (scene text), `ply_mutate`, `run`, `campaign`, `known` (the allow-list of
//! findings already reported, `findings/known.txt`).

pub mod campaign;
pub mod corpus;
pub mod known;
pub mod mutate;
pub mod ply_mutate;
pub mod rng;
pub mod run;
pub mod tokens;
