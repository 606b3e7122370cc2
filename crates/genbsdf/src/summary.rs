//! The report genBSDF prints after a run: what checkBSDF would say of the new file
//! (hemispherical totals per side, the largest T + R, front/back transmission reciprocity),
//! so a user sees the result's plausibility without a second tool.

use std::fmt::Write as _;

use fenestra_bsdf::check;
use fenestra_bsdf::{Bsdf, Direction, Wavelength};

/// A few lines of text (each ending in a newline) summarising the Klems `Visible` blocks of `b`.
pub fn summary(b: &Bsdf) -> String {
    let mut s = String::new();
    let total = |d: Direction| check::component(b, d).map(|c| (c.normal_total, c.diffuse_total));
    for (exterior, name, t, r) in [
        (
            false,
            "light from the room (Back)",
            Direction::TransmissionBack,
            Direction::ReflectionBack,
        ),
        (
            true,
            "light from outside (Front)",
            Direction::TransmissionFront,
            Direction::ReflectionFront,
        ),
    ] {
        let (Some(t), Some(r)) = (total(t), total(r)) else {
            continue;
        };
        let _ = write!(
            s,
            "{name}: T normal {:.4} diffuse {:.4}, R normal {:.4} diffuse {:.4}",
            t.0, t.1, r.0, r.1
        );
        if let Some((most, patch)) = check::energy_balance(b, exterior) {
            let _ = write!(s, "; largest T+R {most:.4} (incident patch {patch})");
            if most > 1.0 {
                s.push_str(" > 1: Monte Carlo noise or a gain");
            }
        }
        s.push('\n');
    }
    let f = b.klems(Direction::TransmissionFront, &Wavelength::Visible);
    let g = b.klems(Direction::TransmissionBack, &Wavelength::Visible);
    if let (Some(f), Some(g)) = (f, g) {
        if let Some(rec) = check::reciprocity(f, g) {
            let _ = writeln!(
                s,
                "transmission reciprocity (Front vs Back mirrored), relative element difference: mean {:.1}%, max {:.1}%",
                100.0 * rec.mean,
                100.0 * rec.max
            );
        }
    }
    s
}
