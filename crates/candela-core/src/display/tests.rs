//! Tests of the live view: a test viewer on 127.0.0.1 receives the stream and
//! decodes it with [`super::decode`], written from tev's protocol
//! description (`tev.rs` module doc), independent of the encoder.

use super::decode::{self, Packet as Decoded};
use super::tev::{self, Rect};
use super::*;
use std::io::Read;
use std::net::{SocketAddr, TcpListener};
use std::sync::mpsc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Decodes one packet (the decoder is `super::decode`, written from the
/// protocol description independently of the encoder).
fn decode(p: &[u8]) -> Decoded {
    decode::decode_packet(p).unwrap()
}

/// Splits a received stream into packets.
fn packets(stream: &[u8]) -> Vec<Decoded> {
    decode::decode_stream(stream).unwrap()
}

/// The image the updates paint and the writes per sample.
fn paint(packets: &[Decoded], w: usize, h: usize, names: &[String]) -> (Vec<Vec<f32>>, Vec<u32>) {
    decode::paint(packets, w, h, names).unwrap()
}

/// Asserts that `img` (per channel) holds exactly the samples of `frame`.
fn assert_pixels(img: &[Vec<f32>], frame: &Frame) {
    let nc = frame.channels().len();
    for (i, &v) in frame.data().iter().enumerate() {
        assert_eq!(img[i % nc][i / nc].to_bits(), v.to_bits(), "sample {i}");
    }
}

/// A frame whose samples differ per pixel, channel and `tag`.
fn test_frame(w: usize, h: usize, names: &[&str], tag: f32) -> Frame {
    let n = names.len();
    let data = (0..w * h * n)
        .map(|i| tag * 1000.0 + i as f32 * 0.5 - 3.0)
        .collect();
    Frame::new(w, h, names.iter().map(|s| s.to_string()).collect(), data).unwrap()
}

/// A viewer on 127.0.0.1 that accepts one connection and returns all bytes
/// read until the client closes it.
fn viewer() -> (SocketAddr, JoinHandle<Vec<u8>>) {
    let l = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = l.local_addr().unwrap();
    (addr, std::thread::spawn(move || read_one(&l)))
}

/// Accepts one connection on `l` and reads it to the end.
fn read_one(l: &TcpListener) -> Vec<u8> {
    let (mut s, _) = l.accept().unwrap();
    let mut v = Vec::new();
    s.read_to_end(&mut v).unwrap();
    v
}

/// An address nobody listens on: the kernel refuses every connection to
/// port 0. (A port freed by dropping a listener is not dead for certain: a
/// test running in parallel may be given it.)
fn dead_address() -> SocketAddr {
    SocketAddr::from(([127, 0, 0, 1], 0))
}

/// Serialises the tests that bind listeners, so that a port one test frees
/// and binds again cannot be handed to another in between.
fn sockets() -> std::sync::MutexGuard<'static, ()> {
    static SOCKETS: std::sync::Mutex<()> = std::sync::Mutex::new(());
    SOCKETS.lock().unwrap_or_else(|e| e.into_inner())
}

/// Options for a test: short timeouts, no retries.
fn options(addr: SocketAddr) -> LiveViewOptions {
    let mut o = LiveViewOptions::new(addr.to_string(), "candela test");
    o.retry_interval = None;
    o
}

/// A warning sink and the warnings it received.
fn warnings() -> (
    impl Fn(&str) + Send + 'static,
    std::sync::Arc<std::sync::Mutex<Vec<String>>>,
) {
    let seen = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
    let s = seen.clone();
    (move |w: &str| s.lock().unwrap().push(w.to_string()), seen)
}

/// Waits (at most 60 s) until `cond` holds.
fn wait_for(what: &str, cond: impl Fn() -> bool) {
    let t = Instant::now();
    while !cond() {
        assert!(
            t.elapsed() < Duration::from_secs(60),
            "timed out waiting for {what}"
        );
        std::thread::sleep(Duration::from_millis(1));
    }
}

#[test]
fn create_packet_matches_the_protocol_bytes() {
    // Derived by hand from tev's `IpcPacket::setCreateImage`: length
    // (including itself), type 4, grab focus, "a\0", width 2, height 3, 1, "R\0".
    let p = tev::encode_create_image("a", true, 2, 3, &["R".into()]).unwrap();
    let want: Vec<u8> = [
        &22u32.to_le_bytes()[..],
        &[4, 1, b'a', 0],
        &2i32.to_le_bytes(),
        &3i32.to_le_bytes(),
        &1i32.to_le_bytes(),
        b"R\0",
    ]
    .concat();
    assert_eq!(p, want);
    let close = tev::encode_close_image("img").unwrap();
    assert_eq!(close, [&9u32.to_le_bytes()[..], &[2], b"img\0"].concat());
    assert!(tev::encode_close_image("a\0b").is_err());
}

#[test]
fn update_packets_cover_an_odd_sized_image_exactly_once() {
    // 300x131 is no multiple of 128; 5 channels exceed one packet per full tile.
    let names = ["R", "G", "B", "albedo.R", "depth.Y"];
    let f = test_frame(300, 131, &names, 1.0);
    let all: Vec<usize> = (0..5).collect();
    let decoded: Vec<Decoded> = tev::update_packets("x", &f, &all, Rect::of(&f))
        .map(|p| decode(&p.unwrap()))
        .collect();
    // 3x2 tiles, one packet each, except that the two full 128x128 tiles
    // carry 4 channels per packet (MAX_PACKET_FLOATS) and so need two.
    assert_eq!(decoded.len(), 6 + 2);
    let (img, writes) = paint(&decoded, 300, 131, f.channels());
    assert!(
        writes.iter().all(|&n| n == 1),
        "each sample sent exactly once"
    );
    assert_pixels(&img, &f);
    // A sub-rectangle of some channels.
    let r = Rect {
        x: 5,
        y: 7,
        width: 3,
        height: 2,
    };
    let one = tev::encode_update_image("x", &f, &[3, 0], r).unwrap();
    let Decoded::Update {
        channels,
        rect,
        data,
        ..
    } = decode(&one)
    else {
        panic!()
    };
    assert_eq!(
        (channels, rect),
        (vec!["albedo.R".into(), "R".into()], [5, 7, 3, 2])
    );
    assert_eq!(data[0][4].to_bits(), f.pixel(6, 8)[3].to_bits());
    assert_eq!(data[1][4].to_bits(), f.pixel(6, 8)[0].to_bits());
    let outside = Rect {
        x: 299,
        y: 0,
        width: 2,
        height: 1,
    };
    assert!(tev::encode_update_image("x", &f, &[0], outside).is_err());
    assert!(tev::encode_update_image("x", &f, &[5], r).is_err());
}

#[test]
fn client_stream_decodes_to_the_frame_sent() {
    let _sockets = sockets();
    let (addr, rx) = viewer();
    let f = test_frame(130, 129, &["R", "G", "B"], 2.0);
    let mut c = TevClient::connect(&addr.to_string(), Duration::from_secs(5)).unwrap();
    c.create_image("img", true, 130, 129, f.channels()).unwrap();
    c.update_frame("img", &f).unwrap();
    c.close_image("img").unwrap();
    drop(c);
    let got = packets(&rx.join().unwrap());
    let create = Decoded::Create {
        grab: true,
        name: "img".into(),
        width: 130,
        height: 129,
        channels: f.channels().to_vec(),
    };
    assert_eq!(got[0], create);
    assert_eq!(got.last(), Some(&Decoded::Close { name: "img".into() }));
    assert_eq!(got.len(), 2 + 4, "2x2 tiles of one packet each");
    let (img, writes) = paint(&got, 130, 129, f.channels());
    assert!(writes.iter().all(|&n| n == 1));
    assert_pixels(&img, &f);
}

#[test]
fn connecting_to_a_dead_address_fails_cleanly() {
    let e = TevClient::connect(&dead_address().to_string(), Duration::from_secs(1));
    assert!(matches!(e, Err(DisplayError::Connect { .. })), "{e:?}");
    let e = TevClient::connect("127.0.0.1:notaport", Duration::from_secs(1));
    assert!(matches!(e, Err(DisplayError::Address { .. })), "{e:?}");
}

#[test]
fn frames_are_validated() {
    let s = |v: &[&str]| v.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    assert!(Frame::new(2, 2, s(&["R"]), vec![0.0; 3]).is_err());
    assert!(Frame::new(0, 2, s(&["R"]), vec![]).is_err());
    assert!(Frame::new(1, 1, s(&["R", "R"]), vec![0.0; 2]).is_err());
    assert!(Frame::new(1, 1, s(&["a\0"]), vec![0.0]).is_err());
    assert!(Frame::new(1, 1, vec![], vec![]).is_err());
    let rgb = crate::image::RgbImage {
        width: 2,
        height: 1,
        pixels: vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]],
    };
    let f = Frame::from_rgb(&rgb).unwrap();
    assert_eq!(
        (f.pixel(1, 0), f.channels()),
        (&[4.0, 5.0, 6.0][..], &s(&["R", "G", "B"])[..])
    );
    let albedo = crate::image::ExrLayer::from_rgb("albedo", &rgb);
    let depth =
        crate::image::ExrLayer::new("", vec![crate::image::ExrChannel::new("Y", vec![7.0, 8.0])]);
    let f = Frame::from_exr_layers(2, 1, &[depth, albedo]).unwrap();
    assert_eq!(
        f.channels(),
        &s(&["Y", "albedo.R", "albedo.G", "albedo.B"])[..]
    );
    assert_eq!(f.pixel(1, 0), &[8.0, 4.0, 5.0, 6.0][..]);
}

#[test]
fn live_view_shows_the_frame_and_keeps_the_image_open() {
    let _sockets = sockets();
    let (addr, rx) = viewer();
    let (warn, seen) = warnings();
    let live = LiveView::start(options(addr), warn).unwrap();
    let f = test_frame(200, 3, &["R", "G", "B", "A", "depth.Y"], 3.0);
    live.send(f.clone());
    let stats = live.finish();
    assert_eq!((stats.submitted, stats.delivered), (1, 1));
    let got = packets(&rx.join().unwrap());
    assert!(
        matches!(&got[0], Decoded::Create { name, width: 200, height: 3, .. } if name == "candela test")
    );
    assert!(!got.iter().any(|p| matches!(p, Decoded::Close { .. })));
    let (img, writes) = paint(&got, 200, 3, f.channels());
    assert!(writes.iter().all(|&n| n == 1));
    assert_pixels(&img, &f);
    assert!(seen.lock().unwrap().is_empty());
}

#[test]
fn a_dead_viewer_costs_one_warning_and_never_blocks() {
    let (warn, seen) = warnings();
    let live = LiveView::start(options(dead_address()), warn).unwrap();
    for k in 0..50 {
        live.send(test_frame(64, 64, &["R", "G", "B"], k as f32));
    }
    let s = live.finish();
    assert_eq!((s.submitted, s.delivered), (50, 0));
    assert_eq!(s.taken + s.superseded, 50);
    let w = seen.lock().unwrap();
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(w[0].contains("cannot connect"), "{}", w[0]);
}

#[test]
fn a_viewer_started_late_is_reconnected() {
    let _sockets = sockets();
    let addr = TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap();
    let (warn, seen) = warnings();
    let mut o = options(addr);
    o.retry_interval = Some(Duration::ZERO);
    let live = LiveView::start(o, warn).unwrap();
    wait_for("the first failed attempt", || {
        seen.lock().unwrap().len() == 1
    });
    // std binds with SO_REUSEADDR on Unix, so the freed port can be taken again.
    let l = TcpListener::bind(addr).unwrap();
    let rx = std::thread::spawn(move || read_one(&l));
    let f = test_frame(5, 4, &["Y"], 4.0);
    live.send(f.clone());
    assert_eq!(live.finish().delivered, 1);
    let got = packets(&rx.join().unwrap());
    assert!(matches!(&got[0], Decoded::Create { .. }));
    assert_pixels(&paint(&got, 5, 4, f.channels()).0, &f);
    assert_eq!(seen.lock().unwrap().len(), 1);
}

#[test]
fn a_stalled_viewer_gets_the_latest_frame_and_the_caller_never_waits() {
    let _sockets = sockets();
    // Frames of 2048x1024x3 floats (25 MB) cannot fit in loopback socket
    // buffers (a few MB), so the worker stalls on frame 1 while nobody reads.
    let l = TcpListener::bind("127.0.0.1:0").unwrap();
    let mut o = options(l.local_addr().unwrap());
    o.write_timeout = Duration::from_secs(600);
    let (warn, seen) = warnings();
    let live = LiveView::start(o, warn).unwrap();
    let frame = |k: usize| test_frame(2048, 1024, &["R", "G", "B"], k as f32);
    live.send(frame(1));
    wait_for("the worker to take frame 1", || live.stats().taken == 1);
    // Frames 2..=10 must go through `send` while the worker is stuck; a
    // watchdog turns a blocking `send` into a failure instead of a hang.
    let (done_tx, done_rx) = mpsc::channel();
    let live = std::sync::Arc::new(live);
    let sender = {
        let live = live.clone();
        std::thread::spawn(move || {
            for k in 2..=10 {
                live.send(frame(k));
            }
            done_tx.send(()).unwrap();
        })
    };
    let r = done_rx.recv_timeout(Duration::from_secs(60));
    assert!(r.is_ok(), "send blocked behind a stalled viewer");
    sender.join().unwrap();
    let Ok(live) = std::sync::Arc::try_unwrap(live) else {
        panic!("live view still shared")
    };
    assert_eq!(live.stats().delivered, 0, "the worker was not stalled");
    let rx = std::thread::spawn(move || read_one(&l));
    let s = live.finish();
    assert_eq!(
        (s.submitted, s.superseded, s.taken, s.delivered),
        (10, 8, 2, 2)
    );
    let got = packets(&rx.join().unwrap());
    let creates = got
        .iter()
        .filter(|p| matches!(p, Decoded::Create { .. }))
        .count();
    assert_eq!(creates, 1, "one image for frames of one layout");
    let last = frame(10);
    let (img, writes) = paint(&got, 2048, 1024, last.channels());
    assert!(writes.iter().all(|&n| n == 2), "frames 1 and 10, whole");
    assert_pixels(&img, &last);
    assert!(seen.lock().unwrap().is_empty());
}
