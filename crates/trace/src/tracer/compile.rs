//! Scene compilation: `Tracer::new` turns a parsed scene into shapes, materials,
//! patterns, light sources and the accelerator, checking what Radiance checks.

use super::*;

impl Tracer {
    /// Prepares `scene` for tracing with `opts`.
    pub fn new(scene: &Scene, opts: &TraceOptions) -> Result<Tracer> {
        let mut shapes = Vec::new();
        let mut surf_prim = Vec::new();
        let mut surf_mat = Vec::new();
        let mut mats: Dense<Material> = Dense::default();
        let mut distant = Vec::new();
        let mut warnings = Vec::new();
        let mut patterns: Dense<Vec<crate::pattern::Pattern>> = Dense::default();
        let mut need_mat = |m: usize, mats: &mut Dense<Material>| -> Result<()> {
            if mats.contains_key(&m) {
                return Ok(());
            }
            let p = &scene.prims[m];
            if is_pattern(&p.ptype) {
                bail!(
                    "{}: '{}' is a {} (pattern), used where a material is expected",
                    p.loc,
                    p.name,
                    p.ptype
                );
            }
            let mut pats = Vec::new();
            for k in scene.modifier_chain(m) {
                pats.push(crate::pattern::compile(
                    scene,
                    k,
                    &p.name,
                    &opts.cal,
                    &opts.resolver,
                )?);
            }
            if !pats.is_empty() {
                patterns.insert(m, pats);
            }
            let mat = compile(scene, m, &opts.resolver)?;
            if let Material::Light {
                kind: LightKind::Illum(Some(a)),
                ..
            } = &mat
            {
                let a = *a;
                mats.insert(m, mat);
                let alt = compile(scene, a, &opts.resolver)?;
                mats.insert(a, alt);
                return Ok(());
            }
            mats.insert(m, mat);
            Ok(())
        };
        for (i, p) in scene.prims.iter().enumerate() {
            if !p.is_surface() {
                continue;
            }
            let Some(m) = p.modifier else { continue };
            let r = &p.rargs;
            let bad = |what: &str| anyhow::anyhow!("{}: {} '{}': {what}", p.loc, p.ptype, p.name);
            let shape = match p.ptype.as_str() {
                t if crate::surface::is_geometry(t) => match crate::surface::shape_of(p)? {
                    crate::surface::Built::Shape(shape, warn) => {
                        warnings.extend(warn);
                        shape
                    }
                    crate::surface::Built::Ignored(warn) => {
                        warnings.push(warn);
                        continue;
                    }
                },
                "source" => {
                    if r.len() != 4 {
                        return Err(bad("needs 4 real arguments"));
                    }
                    need_mat(m, &mut mats)?;
                    let dir = DVec3::new(r[0], r[1], r[2]).normalize_or_zero();
                    if dir == DVec3::ZERO {
                        return Err(bad("zero direction"));
                    }
                    let cos_half = (r[3].to_radians() * 0.5).cos();
                    let glow = matches!(
                        mats[&m],
                        Material::Light {
                            kind: LightKind::Glow(_),
                            ..
                        }
                    );
                    if !mats[&m].is_light() {
                        return Err(bad(
                            "a distant source needs a light, glow, illum or spotlight material",
                        ));
                    }
                    distant.push(Distant {
                        prim: i,
                        mat: m,
                        dir,
                        frame: frame(dir),
                        cos_half,
                        omega: 2.0 * PI * (1.0 - cos_half),
                        glow,
                    });
                    continue;
                }
                other => bail!(
                    "{}: surface type '{other}' of '{}' is not supported by fenestra's ray tracer",
                    p.loc,
                    p.name
                ),
            };
            need_mat(m, &mut mats)?;
            shapes.push(shape);
            surf_prim.push(i);
            surf_mat.push(m);
        }
        // Antimatter: the material of its first modifier shades where rays leave it.
        let firsts: Vec<(usize, usize)> = surf_mat
            .iter()
            .filter_map(|&m| match &mats[&m] {
                Material::Antimatter { first: Some(f), .. } => Some((m, *f)),
                _ => None,
            })
            .collect();
        for (am, f) in firsts {
            need_mat(f, &mut mats)?;
            if matches!(mats[&f], Material::Antimatter { .. }) {
                let p = &scene.prims[am];
                bail!(
                    "{}: antimatter '{}': its first modifier '{}' is itself antimatter",
                    p.loc,
                    p.name,
                    scene.prims[f].name
                );
            }
        }
        for (i, p) in scene.prims.iter().enumerate() {
            if p.ptype == "antimatter" && mats.contains_key(&i) {
                for name in p.sargs.iter().filter(|n| *n != "void") {
                    if scene.find_modifier(name, i).is_none() {
                        warnings.push(format!(
                            "{}: antimatter '{}': unknown modifier '{name}' ignored",
                            p.loc, p.name
                        ));
                    }
                }
            }
        }
        // light sources
        let mut sources = Vec::new();
        for (s, &m) in surf_mat.iter().enumerate() {
            if let Material::Light { color, kind } = &mats[&m] {
                let active = maxc(*color) > FTINY
                    && match kind {
                        LightKind::Glow(r) => *r > FTINY,
                        _ => true,
                    };
                if active {
                    if let Shape::Cone { len, r0, .. } = shapes[s] {
                        let p = &scene.prims[surf_prim[s]];
                        if p.ptype != "cylinder" {
                            // Radiance: "illegal material for cone" (also cup, tube)
                            bail!(
                                "{}: {} '{}' has the light-emitting material '{}': a light, illum, glow \
                                 or spotlight source must be a sphere, polygon, ring, cylinder or \
                                 source (Radiance stops with \"illegal material\" here too)",
                                p.loc,
                                p.ptype,
                                p.name,
                                scene.prims[m].name
                            );
                        }
                        if r0 > 0.2 * len {
                            warnings.push(format!(
                                "{}: cylinder source '{}': aspect too small (radius above 0.2 x length)",
                                p.loc, p.name
                            ));
                        }
                    }
                    // Radiance: "cannot hit source center" (a polygon whose vertex mean
                    // lies outside it, a ring with an inner radius)
                    let p = &scene.prims[surf_prim[s]];
                    let flat = match &shapes[s] {
                        Shape::Polygon(poly) => match FlatSource::polygon(poly) {
                            Ok((f, poor)) => {
                                if poor {
                                    warnings.push(format!(
                                        "{}: polygon source '{}': triangular source with poor aspect",
                                        p.loc, p.name
                                    ));
                                }
                                Some(f)
                            }
                            Err(why) => bail!(
                                "{}: polygon '{}' with the light-emitting material '{}': {why} \
                                 (Radiance stops here too)",
                                p.loc,
                                p.name,
                                scene.prims[m].name
                            ),
                        },
                        Shape::Ring { c, r0, r1, .. } => {
                            if *r0 > 0.0 {
                                bail!(
                                    "{}: ring '{}' with the light-emitting material '{}': cannot hit \
                                     source center (a ring source must have inner radius 0; Radiance \
                                     stops here too)",
                                    p.loc,
                                    p.name,
                                    scene.prims[m].name
                                );
                            }
                            // the normal as written (Radiance normalises it its own way)
                            let a = &p.rargs;
                            // (the shape's n is this vector normalised: same direction)
                            Some(FlatSource::disk(*c, DVec3::new(a[3], a[4], a[5]), *r1))
                        }
                        _ => None,
                    };
                    let cyl = match shapes[s] {
                        Shape::Cone {
                            p0, axis, len, r0, ..
                        } => Some(CylSource::new(p0, axis, len, r0)),
                        _ => None,
                    };
                    sources.push(Source {
                        geom: SourceGeom::Local(s),
                        mat: m,
                        prim: surf_prim[s],
                        flat,
                        cyl,
                    });
                }
            }
        }
        for (k, d) in distant.iter().enumerate() {
            if let Material::Light { color, .. } = &mats[&d.mat] {
                if !d.glow && maxc(*color) > FTINY {
                    sources.push(Source {
                        geom: SourceGeom::Distant(k),
                        mat: d.mat,
                        prim: d.prim,
                        flat: None,
                        cyl: None,
                    });
                }
            }
        }
        // Virtual sources: each distant source seen in each planar mirror (-dr > 0).
        if opts.dr > 0 {
            let real = sources.len();
            for (s, &m) in surf_mat.iter().enumerate() {
                if !matches!(mats[&m], Material::Mirror { .. }) || !shapes[s].is_flat() {
                    continue;
                }
                let n = shapes[s].normal(shapes[s].bounds().0);
                for b in 0..real {
                    if let SourceGeom::Distant(k) = sources[b].geom {
                        let d = distant[k].dir;
                        let dir = d - n * (2.0 * d.dot(n));
                        sources.push(Source {
                            geom: SourceGeom::Virtual {
                                base: b,
                                mirror: s,
                                dir,
                            },
                            mat: sources[b].mat,
                            prim: sources[b].prim,
                            flat: None,
                            cyl: None,
                        });
                    }
                }
            }
        }
        let modifier_of = scene.prims.iter().map(|p| p.modifier).collect();
        let specular = mats.values().any(|m| match m {
            Material::Mirror { .. }
            | Material::Glass { .. }
            | Material::Dielectric { .. }
            | Material::Bsdf(_) => true,
            Material::Normal {
                spec, trans, tspec, ..
            } => *spec > FTINY || (*trans > FTINY && *tspec > FTINY),
            Material::Light { .. } | Material::Antimatter { .. } => false,
        });
        let mut notes = Vec::new();
        let direct = !sources.is_empty() || opts.full;
        notes.push(if sources.is_empty() {
            "direct: off (no light sources in the scene)".to_string()
        } else {
            format!("direct: on ({} light source(s))", sources.len())
        });
        let ambient = opts.ab > 0 || opts.full;
        notes.push(if opts.ab > 0 {
            format!("ambient: on (-ab {})", opts.ab)
        } else {
            "ambient: off (-ab 0)".into()
        });
        notes.push(if specular {
            "specular: on (specular materials present)".into()
        } else {
            "specular: off (no specular materials)".into()
        });
        if opts.full {
            notes.push("effect selection disabled: full integrator".into());
        }
        let passes_shadows = mats.values().any(|m| match m {
            Material::Glass { .. } | Material::Dielectric { .. } => true,
            Material::Normal {
                trans,
                tspec,
                rough,
                ..
            } => *trans > FTINY && *tspec > FTINY && rough * rough <= FTINY,
            Material::Light {
                kind: LightKind::Illum(_),
                ..
            } => true,
            // clipped surfaces let shadow rays through, and so do BSDF proxies
            Material::Antimatter { .. } => true,
            Material::Bsdf(b) => b.thick != 0.0 || b.through,
            _ => false,
        });
        let occlusion_shadows = !passes_shadows && !opts.full;
        notes.push(if passes_shadows {
            "shadow rays: traced through surfaces (glass, illum, antimatter or transmitting materials present)"
                .into()
        } else {
            "shadow rays to distant sources: occlusion test only (no material lets them through)"
                .into()
        });
        let specular = specular || opts.full;
        let most = Self::most_samples(opts, &sources, &shapes);
        let threshold = direct && Self::wants_threshold(opts, most);
        notes.push(if threshold {
            format!(
                "source thresholding: on (-dt {} -dc {}, {} source(s)): only the brightest source samples are shadow-tested",
                opts.dt,
                opts.dc,
                sources.len()
            )
        } else if opts.dt > 0.0 && direct {
            format!(
                "source thresholding: off (-dt {}, but at most {most} source sample(s) per point and the first {} are always tested)",
                opts.dt,
                threshold::MIN_TESTS
            )
        } else {
            format!("source thresholding: off (-dt {}): every source sample is shadow-tested", opts.dt)
        });
        let clipped: Vec<usize> = mats
            .values()
            .filter_map(|m| match m {
                Material::Antimatter { mods, .. } => Some(mods.iter().copied()),
                _ => None,
            })
            .flatten()
            .collect();
        // Radiance's opaque material types (a shadow ray meeting one stops there; a
        // light or spotlight stops shadow rays aimed at other sources)
        let irr_pass = scene
            .prims
            .iter()
            .map(|p| match p.ptype.as_str() {
                // (trans2, interface and mist would pass too, but the material compiler
                // rejects them before this point)
                "trans" | "dielectric" | "glass" | "aBSDF" => true,
                "BSDF" => p.sargs.first().is_some_and(|t| t != "0"),
                _ => false,
            })
            .collect();
        let blocker = surf_mat
            .iter()
            .map(|m| {
                matches!(
                    scene.prims[*m].ptype.as_str(),
                    "plastic" | "metal" | "light" | "spotlight"
                ) && !clipped.contains(m)
            })
            .collect();
        let mut tracer = Tracer {
            accel: Accel::new(shapes),
            surf_prim,
            surf_mat,
            mats,
            modifier_of,
            patterns,
            distant,
            sources,
            opts: opts.clone(),
            effects: Effects {
                direct,
                ambient,
                specular,
                occlusion_shadows,
                notes,
            },
            warnings,
            rays: Default::default(),
            obs: None,
            blocker,
            irr_pass,
        };
        if threshold {
            tracer.obs = Some(tracer.build_caches());
        }
        Ok(tracer)
    }
}
