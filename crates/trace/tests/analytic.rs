//! Analytic checks of the integrator: uniform sky, distant source, interreflection.

use fenestra_trace::{DVec3, TraceOptions, Tracer};

fn scene(text: &str) -> fenestra_scene::Scene {
    fenestra_scene::parse_str(text, "test.rad").unwrap()
}

#[test]
fn uniform_glow_sky_gives_pi_l() {
    // sky of radiance 2 over the upper hemisphere, nothing else
    let s = scene("void glow sky 0 0 4 2 2 2 0\nsky source skydome 0 0 4 0 0 1 180\n");
    let opts = TraceOptions {
        ab: 1,
        ..TraceOptions::rtrace()
    };
    let t = Tracer::new(&s, &opts).unwrap();
    let e = t.irradiance(0, DVec3::ZERO, DVec3::Z);
    for c in e {
        // stratified samples of a constant: exact up to float rounding; required 0.5%
        assert!(
            (c - 2.0 * std::f64::consts::PI).abs() < 0.005 * 2.0 * std::f64::consts::PI,
            "{e:?}"
        );
    }
    // -ab 0: a glow of radius 0 is not a source, so nothing
    let t0 = Tracer::new(&s, &TraceOptions::rtrace()).unwrap();
    assert_eq!(t0.irradiance(0, DVec3::ZERO, DVec3::Z), [0.0; 3]);
}

#[test]
fn distant_source_irradiance_is_l_omega_cos() {
    let s = scene("void light sunmat 0 0 3 1000 1000 1000\nsunmat source sun 0 0 4 0 0.6 0.8 10\n");
    let t = Tracer::new(&s, &TraceOptions::rtrace()).unwrap();
    let e = t.irradiance(0, DVec3::ZERO, DVec3::Z);
    let omega = 2.0 * std::f64::consts::PI * (1.0 - 5f64.to_radians().cos());
    let want = 1000.0 * omega * 0.8;
    // deterministic (-dj 0: one ray to the centre): float rounding only
    assert!((e[0] - want).abs() < 1e-9 * want, "{} vs {want}", e[0]);
    // shadowed by a polygon
    let s2 = scene("void light sunmat 0 0 3 1000 1000 1000\nsunmat source sun 0 0 4 0 0.6 0.8 10\nvoid plastic p 0 0 5 .5 .5 .5 0 0\np polygon blocker 0 0 12 -1 -1 1  1 -1 1  1 2 1  -1 2 1\n");
    let t2 = Tracer::new(&s2, &TraceOptions::rtrace()).unwrap();
    assert_eq!(t2.irradiance(0, DVec3::ZERO, DVec3::Z), [0.0; 3]);
}

#[test]
fn interreflection_inside_a_diffuse_sphere() {
    // bubble of radius R, reflectance rho, small spherical light at the centre:
    // direct irradiance on the wall E0 = Ls * omega is uniform, so L = rho E0 / (pi (1 - rho)).
    let (big_r, r0, ls, rho): (f64, f64, f64, f64) = (2.0, 0.01, 1.0e4, 0.5);
    let text = format!(
        "void plastic wall 0 0 5 {rho} {rho} {rho} 0 0\nwall bubble room 0 0 4 0 0 0 {big_r}\n\
         void light lamp 0 0 3 {ls} {ls} {ls}\nlamp sphere bulb 0 0 4 0 0 0 {r0}\n"
    );
    let s = scene(&text);
    let opts = TraceOptions {
        ab: 30,
        ad: 256,
        lw: 1e-6,
        ..TraceOptions::rtrace()
    };
    let t = Tracer::new(&s, &opts).unwrap();
    let omega = 2.0 * std::f64::consts::PI * (1.0 - (1.0 - (r0 / big_r) * (r0 / big_r)).sqrt());
    let e0 = ls * omega;
    let want = rho * e0 / (std::f64::consts::PI * (1.0 - rho));
    let n = 200;
    let mut sum = 0.0;
    for i in 0..n {
        let a = i as f64 * 0.7;
        let dir = DVec3::new(a.cos(), a.sin(), 0.3 * (a * 1.3).sin());
        sum += t.radiance(i, DVec3::new(0.5, 0.0, 0.0), dir)[1];
    }
    let got = sum / n as f64;
    // Monte Carlo: 256 first-bounce samples x 200 rays; the measured spread of single
    // rays is ~3%, so the mean of 200 is good to ~0.3%; 1.5% allows for the light
    // sphere's own shadow (area ratio 2.5e-5) and 5 standard errors.
    assert!((got - want).abs() < 0.015 * want, "got {got}, want {want}");
}

#[test]
fn effect_selection_gives_the_same_numbers_as_the_full_integrator() {
    // opaque room, sun and sky: the selected integrator uses occlusion-only sun shadows
    let text = "void plastic w 0 0 5 .5 .5 .5 0 0\n\
        w polygon floor 0 0 12 0 0 0  0 4 0  4 4 0  4 0 0\n\
        w polygon wall 0 0 12 0 0 0  4 0 0  4 0 3  0 0 3\n\
        w polygon box 0 0 12 1 1 .5  2 1 .5  2 2 .5  1 2 .5\n\
        void light sun 0 0 3 1e5 1e5 1e5\nsun source s 0 0 4 .3 .4 .8 .5\n\
        void glow sky 0 0 4 1 1 1 0\nsky source d 0 0 4 0 0 1 180\n";
    let s = scene(text);
    let base = TraceOptions {
        ab: 2,
        ad: 64,
        ..TraceOptions::rtrace()
    };
    let sel = Tracer::new(&s, &base).unwrap();
    assert!(sel.effects().occlusion_shadows);
    let full = Tracer::new(&s, &TraceOptions { full: true, ..base }).unwrap();
    assert!(!full.effects().occlusion_shadows);
    for i in 0..20u64 {
        let p = DVec3::new(0.2 * i as f64, 0.1 * i as f64 + 0.5, 0.3);
        assert_eq!(
            sel.irradiance(i, p, DVec3::Z),
            full.irradiance(i, p, DVec3::Z),
            "point {i}"
        );
        let d = DVec3::new(0.1, 0.7, -0.5);
        assert_eq!(sel.radiance(i, p, d), full.radiance(i, p, d), "ray {i}");
    }
}

#[test]
fn clear_dielectric_sphere_conserves_radiance() {
    // no absorption: every path ends on the uniform sky, so radiance = sky radiance
    let s = scene(
        "void glow sky 0 0 4 3 3 3 0\nsky source all 0 0 4 0 0 1 360\n\
         void dielectric water 0 0 5 1 1 1 1.33 0\nwater sphere drop 0 0 4 0 0 0 1\n",
    );
    let t = Tracer::new(&s, &TraceOptions::rtrace()).unwrap();
    for i in 0..20u64 {
        let y = -0.95 + 0.1 * i as f64;
        let v = t.radiance(i, DVec3::new(-5.0, y, 0.1), DVec3::X);
        // Russian roulette below -lw is unbiased but noisy; the hard limit of 10
        // reflections loses at most (max Fresnel)^10 of the weight: 2% allows both.
        assert!((v[0] - 3.0).abs() < 0.06, "ray {i}: {v:?}");
        assert!(v.iter().all(|x| x.is_finite()));
    }
}

#[test]
fn contributions_of_a_tracked_sky_add_up_to_its_irradiance() {
    // open box floor with a sky glow (tracked) and a ground glow (not tracked)
    let s = scene(
        "void plastic grey 0 0 5 .5 .5 .5 0 0\ngrey polygon floor 0 0 12 -5 -5 0  5 -5 0  5 5 0  -5 5 0\n\
         void glow skyglow 0 0 4 2 2 2 0\nskyglow source sky 0 0 4 0 0 1 180\n\
         void glow groundglow 0 0 4 1 1 1 0\ngroundglow source ground 0 0 4 0 0 -1 180\n",
    );
    let opts = TraceOptions {
        ab: 2,
        ad: 256,
        ..TraceOptions::rcontrib()
    };
    let t = Tracer::new(&s, &opts).unwrap();
    let sky = s.prims.iter().position(|p| p.name == "skyglow").unwrap();
    let mut tracked = vec![false; s.prims.len()];
    tracked[sky] = true;
    let (mut coef, mut value) = ([0.0; 3], [0.0; 3]);
    let mut n = 0;
    let p = DVec3::new(0.0, 0.0, 1.0);
    let total = t.contributions_irradiance(3, p, DVec3::Z, &tracked, &mut |c| {
        assert_eq!(c.modifier, sky);
        assert!(c.dir.z >= 0.0 && c.total_dist >= 1e10);
        for k in 0..3 {
            coef[k] += c.coef[k];
            value[k] += c.value[k];
        }
        n += 1;
    });
    assert!(n > 100);
    // upward-facing point above a floor: it sees only the sky, so the coefficient sum is pi
    // (stratified sampling of a constant: exact up to rounding) and the value 2 pi
    assert!((coef[0] - std::f64::consts::PI).abs() < 1e-9, "{coef:?}");
    assert!(
        (value[0] - 2.0 * std::f64::consts::PI).abs() < 1e-9,
        "{value:?}"
    );
    assert!((total[0] - value[0]).abs() < 1e-9);
    // same seed and index without tracking: same irradiance
    assert_eq!(t.irradiance(3, p, DVec3::Z), total);
}
