//! The device's geometry as MGF, for the XML's `<Geometry format="MGF">` (genBSDF
//! `+geom unit`, on by default as in Radiance): the device re-centred on the sample box in
//! x and y (an `xf -t` context, as Radiance's genBSDF writes it), each surface as an MGF
//! face, ring, sphere, cylinder or cone under a material context derived from its Radiance
//! material (colour as CIE x y, diffuse and specular reflectance and transmittance).
//! Renderers that place the device from its BSDF (pkgBSDF, the BSDF material's proxy
//! geometry) read it back.

use std::fmt::Write;

use fenestra_scene::{Primitive, Scene};

/// Modifier types between a surface and its material (followed to the material).
const PASS_THROUGH: &[&str] = &[
    "alias",
    "brightfunc",
    "colorfunc",
    "brightdata",
    "colordata",
    "brighttext",
    "colortext",
    "colorpict",
    "texfunc",
    "texdata",
    "mixfunc",
    "mixdata",
    "mixtext",
    "mixpict",
];

/// Luminance of an RGB triple (Radiance's weights).
fn grey(c: [f64; 3]) -> f64 {
    0.265 * c[0] + 0.670 * c[1] + 0.065 * c[2]
}

/// CIE x y of an RGB colour (Radiance's primaries), grey's when the colour is black.
fn cxy(c: [f64; 3]) -> (f64, f64) {
    let m = fenestra_bsdf::radiance::rgb_to_xyz_matrix();
    let xyz: Vec<f64> = m
        .iter()
        .map(|row| row[0] * c[0] + row[1] * c[1] + row[2] * c[2])
        .collect();
    let s: f64 = xyz.iter().sum();
    if s > 1e-12 {
        (xyz[0] / s, xyz[1] / s)
    } else {
        (1.0 / 3.0, 1.0 / 3.0)
    }
}

/// The MGF material context of a Radiance material (`None`: no surface should use it).
fn material(m: &Primitive) -> String {
    let r = &m.rargs;
    let rgb = |k: usize| {
        [
            r.get(k).copied().unwrap_or(0.0),
            r.get(k + 1).copied().unwrap_or(0.0),
            r.get(k + 2).copied().unwrap_or(0.0),
        ]
    };
    let mut o = format!("m {} =\n", m.name);
    let (x, y) = cxy(rgb(0));
    let c = format!("\tc\n\t\tcxy {x:.4} {y:.4}\n");
    let g = grey(rgb(0));
    let (spec, rough) = (
        r.get(3).copied().unwrap_or(0.0),
        r.get(4).copied().unwrap_or(0.0),
    );
    match m.ptype.as_str() {
        "plastic" | "plastic2" => {
            let _ = write!(
                o,
                "{c}\trd {:.4}\n\tc\n\trs {spec:.4} {rough:.4}\n",
                (1.0 - spec) * g
            );
        }
        "metal" | "metal2" => {
            let _ = write!(
                o,
                "{c}\trd {:.4}\n{c}\trs {:.4} {rough:.4}\n",
                (1.0 - spec) * g,
                spec * g
            );
        }
        "trans" | "trans2" => {
            let (t, ts) = (
                r.get(5).copied().unwrap_or(0.0),
                r.get(6).copied().unwrap_or(0.0),
            );
            let d = (1.0 - spec) * g;
            let _ = write!(
                o,
                "{c}\trd {:.4}\n{c}\ttd {:.4}\n{c}\tts {:.4} {rough:.4}\n\tc\n\trs {spec:.4} {rough:.4}\n",
                d * (1.0 - t),
                d * t * (1.0 - ts),
                d * t * ts
            );
        }
        "glass" | "dielectric" => {
            let _ = write!(o, "{c}\tts {:.4} 0\n\tc\n\trs 0.08 0\n", g);
        }
        "mirror" => {
            let _ = writeln!(o, "{c}\trs {g:.4} 0");
        }
        _ => {
            let _ = writeln!(o, "{c}\trd {g:.4}");
        }
    }
    o
}

/// Writes vertex `name` at `p` (with normal `n` when given).
fn vertex(o: &mut String, name: &str, p: [f64; 3], n: Option<[f64; 3]>) {
    let _ = writeln!(o, "v {name} =\n\tp {} {} {}", p[0], p[1], p[2]);
    if let Some(n) = n {
        let _ = writeln!(o, "\tn {} {} {}", n[0], n[1], n[2]);
    }
}

/// The MGF text of the device's surfaces in `scene`, translated so that the sample box
/// `dim` (`[x0, x1, y0, y1, z0, z1]`) is centred on x = y = 0. Surfaces MGF cannot hold
/// (e.g. `source`, `instance`) are left out.
pub fn device_mgf(scene: &Scene, dim: &[f64; 6]) -> String {
    let mut o = String::new();
    let _ = writeln!(
        o,
        "xf -t {:.6} {:.6} 0",
        -(dim[0] + dim[1]) / 2.0,
        -(dim[2] + dim[3]) / 2.0
    );
    let mut written = vec![false; scene.prims.len()];
    let mut nv = 0usize;
    let mut current = None;
    for p in &scene.prims {
        if !p.is_surface() {
            continue;
        }
        // the material: the modifier itself when it is a material (aliases and patterns
        // are followed to the first material)
        let mut m = p.modifier;
        while let Some(k) = m {
            let q = &scene.prims[k];
            if PASS_THROUGH.contains(&q.ptype.as_str()) {
                m = q.modifier;
            } else {
                break;
            }
        }
        let Some(mk) = m else { continue };
        if !written[mk] {
            o.push_str(&material(&scene.prims[mk]));
            written[mk] = true;
        }
        let r = &p.rargs;
        let pt = |k: usize| [r[k], r[k + 1], r[k + 2]];
        let mut v = |o: &mut String, at: [f64; 3], n: Option<[f64; 3]>| {
            nv += 1;
            let name = format!("v{nv}");
            vertex(o, &name, at, n);
            name
        };
        if current != Some(mk) {
            let _ = writeln!(o, "m {}", scene.prims[mk].name);
            current = Some(mk);
        }
        match p.ptype.as_str() {
            "polygon" if r.len() >= 9 && r.len() % 3 == 0 => {
                let names: Vec<String> = (0..r.len() / 3)
                    .map(|k| v(&mut o, pt(3 * k), None))
                    .collect();
                let _ = writeln!(o, "f {}", names.join(" "));
            }
            "ring" if r.len() >= 8 => {
                let c = v(&mut o, pt(0), Some(pt(3)));
                let _ = writeln!(o, "ring {c} {} {}", r[6], r[7]);
            }
            "sphere" | "bubble" if r.len() >= 4 => {
                let c = v(&mut o, pt(0), None);
                let rad = if p.ptype == "bubble" { -r[3] } else { r[3] };
                let _ = writeln!(o, "sph {c} {rad}");
            }
            "cylinder" | "tube" if r.len() >= 7 => {
                let (a, b) = (v(&mut o, pt(0), None), v(&mut o, pt(3), None));
                let rad = if p.ptype == "tube" { -r[6] } else { r[6] };
                let _ = writeln!(o, "cyl {a} {rad} {b}");
            }
            "cone" | "cup" if r.len() >= 8 => {
                let (a, b) = (v(&mut o, pt(0), None), v(&mut o, pt(3), None));
                let s = if p.ptype == "cup" { -1.0 } else { 1.0 };
                let _ = writeln!(o, "cone {a} {} {b} {}", s * r[6], s * r[7]);
            }
            _ => {}
        }
    }
    o.push_str("xf\n");
    o
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn faces_materials_and_centring() {
        let mut parser = fenestra_scene::Parser::new();
        parser
            .add_str(
                "void plastic white 0 0 5 .8 .8 .8 .04 .02\n\
                 white polygon slat 0 0 12 0 0 -1  2 0 -1  2 1 -1  0 1 -1\n\
                 white sphere ball 0 0 4 1 .5 -.5 .1\n",
                "t.rad",
            )
            .unwrap();
        let scene = parser.finish();
        let mgf = device_mgf(&scene, &[0.0, 2.0, 0.0, 1.0, -1.0, 0.0]);
        assert!(
            mgf.starts_with("xf -t -1.000000 -0.500000 0\n") && mgf.ends_with("xf\n"),
            "{mgf}"
        );
        assert_eq!(mgf.matches("m white =").count(), 1, "{mgf}");
        assert!(
            mgf.contains("rd 0.7680") && mgf.contains("rs 0.0400 0.0200"),
            "{mgf}"
        );
        assert!(
            mgf.contains("f v1 v2 v3 v4") && mgf.contains("sph v5 0.1"),
            "{mgf}"
        );
        // grey: CIE x y of the white point of Radiance's primaries (equal energy)
        assert!(mgf.contains("cxy 0.3333 0.3333"), "{mgf}");
    }

    #[test]
    fn the_blind_reads_back_from_its_mgf() {
        // the example blind (MGF in): its embedded MGF, parsed again, holds the same faces,
        // moved by the centring translation
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../examples/genbsdf/blinds_curved20.mgf"
        );
        let text = std::fs::read(path).unwrap();
        let mut parser = fenestra_scene::Parser::new();
        parser
            .add_mgf(&fenestra_scene::decode_text(text), path)
            .unwrap();
        let scene = parser.finish();
        let dim = [0.0, 0.3, 0.0, 0.28, -0.03, 0.0];
        let mgf = device_mgf(&scene, &dim);
        let mut back = fenestra_scene::Parser::new();
        back.add_mgf(&mgf, "embedded").unwrap();
        let back = back.finish();
        let polys = |s: &Scene| -> Vec<Vec<f64>> {
            s.prims
                .iter()
                .filter(|p| p.ptype == "polygon")
                .map(|p| p.rargs.clone())
                .collect()
        };
        let (a, b) = (polys(&scene), polys(&back));
        assert!(!a.is_empty());
        assert_eq!(a.len(), b.len());
        for (pa, pb) in a.iter().zip(&b) {
            assert_eq!(pa.len(), pb.len());
            for k in 0..pa.len() / 3 {
                assert!((pa[3 * k] - 0.15 - pb[3 * k]).abs() < 1e-9);
                assert!((pa[3 * k + 1] - 0.14 - pb[3 * k + 1]).abs() < 1e-9);
                assert!((pa[3 * k + 2] - pb[3 * k + 2]).abs() < 1e-9);
            }
        }
    }
}
