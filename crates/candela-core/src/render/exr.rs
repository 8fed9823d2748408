//! A render's layered EXR in memory: the bytes `candela render` and
//! `candela merge` write, for library users that write the file themselves
//! or send it elsewhere (the Python module, a cluster's client).
//!
//! Channels named `layer.C` go to layer `layer` as channel `C` (split at the
//! last '.'), the others to the root layer; the header holds the passes in
//! the image, the passes planned and the integrator's name. The encoder
//! ([`encode_exr_layers`]) is a pure function of its arguments, so equal
//! states give equal files on any machine running the same binary.

use super::{develop_state, RenderState};
use crate::build::RenderSetup;
use crate::film::Developed;
use crate::image::{
    encode_exr_layers, ExrAttribute, ExrAttributes, ExrChannel, ExrLayer, ImageError,
};

/// The developed channels as EXR layers (root layer `""` first seen first).
pub fn exr_layers(dev: &Developed) -> Vec<ExrLayer> {
    let mut out: Vec<ExrLayer> = Vec::new();
    for ch in &dev.channels {
        let (layer, name) = ch.name.rsplit_once('.').unwrap_or(("", ch.name.as_str()));
        let c = ExrChannel::new(name, ch.data.clone());
        match out.iter_mut().find(|l| l.name == layer) {
            Some(l) => l.channels.push(c),
            None => out.push(ExrLayer::new(layer, vec![c])),
        }
    }
    out
}

/// Header attributes: how many passes the image holds, of how many planned.
pub fn exr_attributes(dev: &Developed, integrator: &str, total_passes: u64) -> ExrAttributes {
    let mut a = ExrAttributes::new();
    let int = |v: u64| ExrAttribute::Int(i32::try_from(v).unwrap_or(i32::MAX));
    a.insert("candela.passes".into(), int(dev.passes));
    a.insert("candela.plannedPasses".into(), int(total_passes));
    a.insert(
        "candela.integrator".into(),
        ExrAttribute::Text(integrator.to_string()),
    );
    if !dev.units.is_empty() {
        a.insert(
            "candela.units".into(),
            ExrAttribute::Text("photometric".into()),
        );
    }
    for (layer, unit) in &dev.units {
        a.insert(
            format!("{layer}.units"),
            ExrAttribute::Text(unit.to_string()),
        );
    }
    a
}

/// The bytes of the EXR of `state` developed with `setup` (the integrator's
/// overlay included), as the command line writes it.
pub fn encode_exr(setup: &RenderSetup, state: &RenderState) -> Result<Vec<u8>, ImageError> {
    let dev = develop_state(setup, state);
    let attrs = exr_attributes(&dev, &state.integrator, state.total_passes);
    encode_exr_layers(dev.width, dev.height, &exr_layers(&dev), &attrs)
}
