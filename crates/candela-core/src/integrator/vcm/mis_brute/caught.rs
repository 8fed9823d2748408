//! The brute-force check can fail: densities or factors given to the
//! recursion that are not the path's are caught ([`super`]).

use super::{brute_force, compare, paths, Path, Technique, DIRECT};
use super::{DirectMerges, Emitter};

/// Over the first `n` random paths that `keep` accepts and on which the
/// techniques `uses` carry at least `min_share` of the (brute-force)
/// weight, compares the recursion given `perturb(path)` with the truth:
/// (caught, tried), caught counting the paths the main test's criterion
/// rejects.
fn catches(
    n: usize,
    direct: DirectMerges,
    keep: impl Fn(&Path) -> bool,
    uses: impl Fn(&Path, &Technique) -> bool,
    min_share: f64,
    perturb: impl Fn(&Path) -> Path,
) -> (u32, u32) {
    let (mut caught, mut tried) = (0, 0);
    for p in paths().take(n) {
        if !keep(&p) || p.delta[1..].iter().any(|&d| d) {
            continue;
        }
        let brute = brute_force(&p, direct);
        let total: f64 = brute.iter().map(|(_, q)| q * q).sum();
        let share: f64 = brute
            .iter()
            .filter(|(t, _)| uses(&p, t))
            .map(|(_, q)| q * q / total)
            .sum();
        if share < min_share {
            continue;
        }
        let Some(m) = compare(&p, &perturb(&p), direct) else {
            continue;
        };
        tried += 1;
        caught += !m.agrees() as u32;
    }
    (caught, tried)
}

/// The check can fail: a density given to the recursion that is not the
/// path's (x_2's camera-side direction density, that of x_1, 30 % high) is
/// caught by the main test's criterion on every path of 2+ segments
/// without specular vertices in which the techniques that use it (the
/// camera subpath making x_1: s ≤ 1, a merge at x_1) carry more than 1e-6
/// of the weight; without merges next to the light they can carry less
/// than 1e-9, below any tolerance.
#[test]
fn a_perturbed_density_is_caught() {
    for direct in DIRECT {
        let (caught, tried) = catches(
            600,
            direct,
            |p| p.m() >= 2,
            |_, t| matches!(t, Technique::Connect(0 | 1) | Technique::Merge(1)),
            1e-6,
            |p| {
                let mut given = p.clone();
                given.pe_dir[2] *= 1.3;
                given
            },
        );
        assert!(
            tried > 50 && caught == tried,
            "{direct:?}: {caught}/{tried}"
        );
    }
}

/// An area light's next-event density is its own technique's: giving the
/// recursion the emission's position density instead (the weights before
/// `nee_area_density`, right only for area-uniform sampling) is caught on
/// every area-light path without specular vertices where next-event
/// estimation or a hit on the light carries more than 1e-3 of the weight
/// and the two densities differ by more than 20 %.
#[test]
fn the_next_event_density_is_the_samplers() {
    let (caught, tried) = catches(
        1200,
        DirectMerges::AfterSpecular,
        |p| p.m() > 0 && p.light == Emitter::Area && (p.p_nee / p.p_pos - 1.0).abs() > 0.2,
        |_, t| matches!(t, Technique::Connect(0 | 1)),
        1e-3,
        |p| Path {
            p_nee: p.p_pos,
            ..p.clone()
        },
    );
    assert!(tried > 50 && caught == tried, "{caught}/{tried}");
}

/// A light seen from the lens is weighed against light tracing's join of
/// its point x_0 with the emission's position density (selection × area),
/// which sampled x_0: weighing both with the next-event density instead is
/// caught on every such area-light path where the two differ by more than
/// 20 % and each technique carries more than 1e-3 of the weight.
#[test]
fn a_light_seen_directly_is_weighed_with_its_position_density() {
    let (caught, tried) = catches(
        2800,
        DirectMerges::AfterSpecular,
        |p| p.m() == 0 && p.light == Emitter::Area && (p.p_nee / p.p_pos - 1.0).abs() > 0.2,
        |_, t| *t == Technique::Connect(0),
        1e-3,
        |p| Path {
            p_pos: p.p_nee,
            ..p.clone()
        },
    );
    assert!(tried > 50 && caught == tried, "{caught}/{tried}");
}

/// Light tracing's variance factor is in every weight: giving the recursion
/// c = 1 (density alone) where the path's is below 0.8 is caught on every
/// path without specular vertices where light tracing carries more than
/// 1e-3 of the weight.
#[test]
fn the_light_tracing_factor_is_applied() {
    let (caught, tried) = catches(
        1200,
        DirectMerges::AfterSpecular,
        |p| p.lt_c <= 0.8,
        |p, t| *t == Technique::Connect(p.m() + 1),
        1e-3,
        |p| Path {
            lt_c: 1.0,
            ..p.clone()
        },
    );
    assert!(tried > 50 && caught == tried, "{caught}/{tried}");
}

/// With a radius field each merge technique has the η of its own vertex:
/// giving the recursion one radius for the whole path (x_1's) where the
/// radius at some other vertex differs from it by more than 30 % is caught
/// on every path without specular vertices where the merges carry more
/// than 1e-3 of the weight.
#[test]
fn each_merge_has_its_own_vertexs_radius() {
    let differs = |p: &Path| {
        p.radius[1..]
            .iter()
            .any(|&r| (r / p.radius[1] - 1.0).abs() > 0.3)
    };
    let (caught, tried) = catches(
        1200,
        DirectMerges::Always,
        |p| p.m() >= 2 && differs(p),
        |_, t| matches!(t, Technique::Merge(_)),
        1e-3,
        |p| Path {
            radius: vec![p.radius[1]; p.radius.len()],
            ..p.clone()
        },
    );
    assert!(tried > 50 && caught == tried, "{caught}/{tried}");
}
