//! candela-scene: reads pbrt-v4 scene files into a plain description.
