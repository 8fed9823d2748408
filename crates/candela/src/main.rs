//! The `candela` command-line renderer.
fn main() {}
