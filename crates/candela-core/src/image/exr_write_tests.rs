//! Tests of `exr_write`: equal content gives equal bytes, the round trip is
//! exact, and the main RGB layer is what RGB readers find.

use super::*;
use crate::image::{read_map, ColorEncoding, WrapMode};

/// A fresh empty directory for one test.
fn test_dir(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("candela-exrw-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Awkward floats: signed zero, infinities, NaN with a payload, subnormals.
const SPECIAL: [f32; 8] = [
    -0.0,
    f32::INFINITY,
    f32::NEG_INFINITY,
    f32::MIN_POSITIVE / 8.0,
    1e30,
    -3.25,
    f32::EPSILON,
    0.1,
];

/// Samples of channel number `k`: distinct per channel and pixel, with the
/// special values mixed in.
fn samples(k: usize, n: usize) -> Vec<f32> {
    (0..n)
        .map(|i| match (i + k) % 11 {
            0..=7 => SPECIAL[(i + k) % 8],
            8 => f32::from_bits(0x7fc0_1234 + k as u32), // NaN with a payload
            _ => (i * 31 + k) as f32 * 0.37 - 40.0,
        })
        .collect()
}

/// 7x37 pixels (odd sizes, 37 scan-line blocks),
/// the layers a G-buffer film writes, and attributes of every type.
fn sample_image() -> ExrImage {
    let (w, h) = (7, 37);
    let mut k = 0;
    let mut layer = |name: &str, chans: &[&str]| {
        let channels = chans
            .iter()
            .map(|c| {
                k += 1;
                ExrChannel::new(*c, samples(k, w * h))
            })
            .collect();
        ExrLayer::new(name, channels)
    };
    let layers = vec![
        layer("", &["R", "G", "B", "dzdx", "u"]),
        layer("albedo", &["R", "G", "B"]),
        layer("depth", &["Y"]),
        layer("P", &["X", "Y", "Z"]),
        layer("Ns", &["X", "Y", "Z"]),
        layer("Variance", &["R", "G", "B"]),
        layer("spectral.S0", &["400nm", "410nm"]),
    ];
    let attributes = ExrAttributes::from([
        ("candela.passes".into(), ExrAttribute::Int(16)),
        (
            "candela.units".into(),
            ExrAttribute::Text("W/(m² sr)".into()),
        ),
        ("candela.radius".into(), ExrAttribute::Float(0.125)),
        ("candela.seconds".into(), ExrAttribute::Double(12.5e-3)),
        (
            "candela.integrator".into(),
            ExrAttribute::Text("sppm".into()),
        ),
        ("candela.seed".into(), ExrAttribute::Int(-7)),
    ]);
    ExrImage {
        width: w,
        height: h,
        layers,
        attributes,
    }
}

/// `img` as reading gives it back: layers by name, channels by name.
fn file_order(mut img: ExrImage) -> ExrImage {
    img.layers.sort_by(|a, b| a.name.cmp(&b.name));
    for l in &mut img.layers {
        l.channels.sort_by(|a, b| a.name.cmp(&b.name));
    }
    img
}

/// Asserts equal content, comparing samples bit for bit (NaN included).
fn assert_same(got: &ExrImage, want: &ExrImage) {
    assert_eq!((got.width, got.height), (want.width, want.height));
    assert_eq!(got.attributes, want.attributes);
    let names = |i: &ExrImage| -> Vec<(String, Vec<String>)> {
        i.layers
            .iter()
            .map(|l| {
                (
                    l.name.clone(),
                    l.channels.iter().map(|c| c.name.clone()).collect(),
                )
            })
            .collect()
    };
    assert_eq!(names(got), names(want));
    for (lg, lw) in got.layers.iter().zip(&want.layers) {
        for (cg, cw) in lg.channels.iter().zip(&lw.channels) {
            let bits = |c: &ExrChannel| c.samples.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(cg), bits(cw), "{}.{}", lg.name, cg.name);
        }
    }
}

#[test]
fn equal_content_gives_equal_bytes() {
    let img = sample_image();
    let enc = || encode_exr_layers(img.width, img.height, &img.layers, &img.attributes).unwrap();
    // Each encoding builds a fresh attribute HashMap inside `exr`, with its
    // own random iteration order: unsorted headers differ between these.
    let first = enc();
    for _ in 0..4 {
        assert!(first == enc(), "EXR bytes differ between equal encodings");
    }
    let d = test_dir("bytes");
    let (a, b) = (d.join("a.exr"), d.join("b.exr"));
    img.write(&a).unwrap();
    img.write(&b).unwrap();
    let a = std::fs::read(&a).unwrap();
    assert!(a == std::fs::read(&b).unwrap() && a == first);
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn attributes_are_stored_sorted_by_name() {
    let img = sample_image();
    let bytes = encode_exr_layers(img.width, img.height, &img.layers, &img.attributes).unwrap();
    let (records, _) = header_records(&bytes, 8).unwrap();
    let names: Vec<&[u8]> = records
        .iter()
        .map(|r| &bytes[r.start..r.name_end])
        .collect();
    let mut sorted = names.clone();
    sorted.sort();
    assert_eq!(names, sorted);
    // The standard ones and our six custom ones are all there.
    assert!(names.contains(&&b"channels"[..]) && names.contains(&&b"candela.seed"[..]));
    assert!(names.len() >= 6 + 8);
}

#[test]
fn round_trip_of_layers_channels_and_attributes_is_exact() {
    let img = sample_image();
    let d = test_dir("round");
    let p = d.join("layers.exr");
    img.write(&p).unwrap();
    let back = read_exr_layers(&p).unwrap();
    assert_same(&back, &file_order(img));
    assert_eq!(
        back.channel("spectral.S0", "410nm").map(|s| s.len()),
        Some(7 * 37)
    );
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn rgb_readers_find_the_main_layer() {
    let mut img = sample_image();
    let main = img.layers[0].clone();
    // Put the albedo layer first: file order, not argument order, decides.
    img.layers.swap(0, 1);
    let d = test_dir("rgb");
    let p = d.join("main.exr");
    img.write(&p).unwrap();
    let rgb = RgbImage::read_exr(&p).unwrap();
    assert_eq!((rgb.width, rgb.height), (7, 37));
    for (i, px) in rgb.pixels.iter().enumerate() {
        for (c, name) in ["R", "G", "B"].iter().enumerate() {
            assert_eq!(px[c].to_bits(), main.channel(name).unwrap()[i].to_bits());
        }
    }
    let map = read_map(&p, ColorEncoding::Linear).unwrap();
    let texel = map.image.texel(3, 5, 0, WrapMode::Black);
    assert_eq!(
        texel.to_bits(),
        main.channel("R").unwrap()[5 * 7 + 3].to_bits()
    );
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn rgb_image_write_is_deterministic_and_exact() {
    let mut img = RgbImage::new(130, 17);
    for (i, p) in img.pixels.iter_mut().enumerate() {
        *p = [i as f32 * 0.25, 1e-7 * i as f32, -(i as f32)];
    }
    let d = test_dir("rgbimage");
    let (a, b) = (d.join("a.exr"), d.join("b.exr"));
    img.write_exr(&a).unwrap();
    img.write_exr(&b).unwrap();
    assert!(std::fs::read(&a).unwrap() == std::fs::read(&b).unwrap());
    assert_eq!(RgbImage::read_exr(&a).unwrap(), img);
    let back = read_exr_layers(&a).unwrap();
    assert_same(
        &back,
        &file_order(ExrImage {
            width: 130,
            height: 17,
            layers: vec![ExrLayer::from_rgb("", &img)],
            attributes: ExrAttributes::new(),
        }),
    );
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn bad_content_is_refused_and_the_old_file_kept() {
    let img = sample_image();
    let d = test_dir("bad");
    let p = d.join("keep.exr");
    img.write(&p).unwrap();
    let before = std::fs::read(&p).unwrap();
    let n = img.width * img.height;
    let one = |layer: &str, chan: &str, len: usize| {
        vec![ExrLayer::new(
            layer,
            vec![ExrChannel::new(chan, vec![0.0; len])],
        )]
    };
    let none = ExrAttributes::new();
    let cases: Vec<(Vec<ExrLayer>, ExrAttributes)> = vec![
        (one("", "P.X", n), none.clone()),   // dot in a channel name
        (one("", "R", n - 1), none.clone()), // wrong sample count
        (one(".a", "R", n), none.clone()),   // layer name starts with a dot
        (vec![ExrLayer::new("x", vec![])], none.clone()),
        ([one("a", "R", n), one("a", "R", n)].concat(), none.clone()),
        (
            one("", "R", n),
            ExrAttributes::from([("channels".into(), ExrAttribute::Int(1))]),
        ),
        (vec![], none.clone()),
    ];
    for (layers, attributes) in cases {
        let r = write_exr_layers(&p, img.width, img.height, &layers, &attributes);
        assert!(r.is_err(), "accepted {layers:?} {attributes:?}");
    }
    assert!(write_exr_layers(&p, 0, 5, &[], &none).is_err());
    assert!(std::fs::read(&p).unwrap() == before);
    let left: Vec<_> = std::fs::read_dir(&d).unwrap().collect();
    assert_eq!(left.len(), 1);
    std::fs::remove_dir_all(&d).ok();
}
