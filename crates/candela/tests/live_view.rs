//! `candela render --display-server`: a test viewer (a `TcpListener` on
//! 127.0.0.1) receives well-formed tev packets whose last image is, bit for
//! bit, every channel of the EXR written; a viewer that is not there costs
//! a warning and nothing else.

use candela_core::display::decode::{decode_stream, paint, Packet};
use candela_core::image::read_exr_layers;
use std::io::Read;
use std::net::TcpListener;
use std::process::Command;

fn candela() -> Command {
    Command::new(env!("CARGO_BIN_EXE_candela"))
}

const SCENE: &str = r#"LookAt 0 0 -3  0 0 0  0 1 0
Camera "perspective"
Film "rgb" "integer xresolution" [37] "integer yresolution" [21]
Sampler "independent" "integer pixelsamples" [6]
Integrator "path"
WorldBegin
LightSource "infinite" "rgb L" [0.4 0.5 0.6]
Material "diffuse"
Shape "sphere"
"#;

fn tmpdir(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("candela-live-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn the_viewer_receives_the_channels_of_the_written_exr() {
    let d = tmpdir("view");
    let scene = d.join("s.pbrt");
    std::fs::write(&scene, SCENE).unwrap();
    let l = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = l.local_addr().unwrap().to_string();
    let viewer = std::thread::spawn(move || {
        let (mut s, _) = l.accept().unwrap();
        let mut v = Vec::new();
        s.read_to_end(&mut v).unwrap();
        v
    });
    let out = d.join("out.exr");
    let o = candela()
        .arg("render")
        .arg(&scene)
        .args([
            "--aov",
            "albedo,depth,variance",
            "--display-server",
            &addr,
            "--outfile",
        ])
        .arg(&out)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("live view: ") && !err.contains("warning: live view"),
        "{err}"
    );
    let packets = decode_stream(&viewer.join().unwrap()).expect("well-formed tev packets");
    let Some(Packet::Create {
        name,
        width,
        height,
        channels,
        ..
    }) = packets
        .iter()
        .rev()
        .find(|p| matches!(p, Packet::Create { .. }))
        .cloned()
    else {
        panic!("no image created: {packets:?}")
    };
    assert_eq!((name.as_str(), width, height), ("s.pbrt", 37, 21));
    let (img, writes) = paint(&packets, 37, 21, &channels).expect("tiles inside the image");
    assert!(writes.iter().all(|&n| n >= 1), "every sample sent");
    let exr = read_exr_layers(&out).unwrap();
    let mut compared = 0;
    for layer in &exr.layers {
        for ch in &layer.channels {
            let full = if layer.name.is_empty() {
                ch.name.clone()
            } else {
                format!("{}.{}", layer.name, ch.name)
            };
            let c = channels
                .iter()
                .position(|n| *n == full)
                .unwrap_or_else(|| panic!("{full} not sent: {channels:?}"));
            for (i, v) in ch.samples.iter().enumerate() {
                assert_eq!(img[c][i].to_bits(), v.to_bits(), "{full} sample {i}");
            }
            compared += 1;
        }
    }
    assert_eq!(compared, channels.len());
    assert_eq!(compared, 3 + 3 + 1 + 3);
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn an_absent_viewer_costs_a_warning_and_the_same_image() {
    let d = tmpdir("absent");
    let scene = d.join("s.pbrt");
    std::fs::write(&scene, SCENE).unwrap();
    // Port 0 can never be connected to (the kernel refuses it), so this
    // viewer is absent for certain. A port freed by dropping a listener is
    // not: the other test, running in parallel, may be given it.
    let dead = "127.0.0.1:0".to_string();
    let render = |extra: &[&str], out: &str| {
        let o = candela()
            .arg("render")
            .arg(&scene)
            .args(extra)
            .args(["--seed", "3", "--outfile"])
            .arg(d.join(out))
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stderr).to_string()
    };
    let err = render(&["--display-server", &dead], "a.exr");
    assert!(
        err.contains("warning: live view") && err.contains(&dead),
        "{err}"
    );
    render(&[], "b.exr");
    assert!(std::fs::read(d.join("a.exr")).unwrap() == std::fs::read(d.join("b.exr")).unwrap());
    std::fs::remove_dir_all(&d).ok();
}
