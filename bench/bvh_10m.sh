#!/bin/sh
# Builds a 10M-triangle scene (the BVH bench's displaced sphere at 2·2237²
# triangles, as opaque triangle primitives through Scene::new) and prints the
# build time, the BVH's bytes per triangle and the process's peak resident
# memory, which must stay well inside the machine's 24 GiB.
#
#     sh bench/bvh_10m.sh [N]     # 2·N² triangles, N = 2237 by default
set -e
cd "$(dirname "$0")/.."
cargo run -q --release -p candela-core --example scene_10m -- "$@"
