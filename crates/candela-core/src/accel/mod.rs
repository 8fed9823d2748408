//! Acceleration structures for ray queries over many primitives.
//!
//! An 8-wide bounding volume hierarchy, built in two stages as Embree and
//! most CPU ray tracers do (Wald et al. 2008, "Getting rid of packets";
//! Wald et al. 2014, "Embree: a kernel framework for efficient CPU ray
//! tracing"):
//!
//! 1. **Binary SAH build** ([`build`]): binned over all three axes, with a
//!    leaf cost counted in packs of four primitives; it terminates on any
//!    input, and its depth is bounded.
//! 2. **Collapse** ([`bvh`]): each wide node takes the binary node's
//!    children and opens the largest interior one until it has eight. Nodes
//!    hold their children's boxes as one 8-lane vector per axis and bound
//!    (256 bytes, four cache lines). Leaves hold at most two packs.
//!
//! Why eight: incoherent rays over a large mesh wait on memory, one node
//! after another, far more than they compute. On the bench mesh (about a
//! million triangles) a closest-hit ray visits 7.5 eight-wide nodes against
//! 11.0 four-wide ones, for the same 1.26 triangle packs; the 8-lane tests
//! run as two SSE halves (`wide` without AVX at compile time), which costs
//! little next to a cache miss.
//!
//! Triangles are copied into the leaves as [`triangle4`] packs: four
//! triangles' vertices in structure-of-arrays form, tested together by a
//! SIMD version of the watertight test that rounds exactly as the scalar one
//! does, so hits, `t` and barycentrics (and so the interaction's error
//! bounds and spawned-ray offsets) are those of
//! [`crate::shape::WatertightRay`]. Other items (quadrics, bilinear patches,
//! alpha-tested triangles, moving groups) sit in the same packs as tagged
//! lanes and are tested through a closure.
//!
//! **Traversal.** Closest hit: the eight slab tests of a node run at once;
//! hit children are visited nearest first and the others pushed with their
//! entry distance on a small fixed stack, and skipped when popped if the
//! closest hit found since is nearer. Any hit (shadow rays): no ordering,
//! and the first hit ends the walk.

mod build;
mod bvh;
#[cfg(test)]
mod tests;
mod triangle4;

pub use bvh::{Bvh, BvhHit};
