//! Shading of emitters (light, illum, glow, spotlight) and pattern evaluation.

use super::*;

impl Tracer {
    /// An emitter `m` (object `prim`) met by `r` at `at` (`None`: a distant source).
    pub(super) fn shade_light(
        &self,
        r: &Ray,
        m: usize,
        prim: usize,
        at: Option<&Surf>,
        cx: &mut Ctx,
    ) -> (DVec3, bool) {
        let (rod, t, p) = at.map_or((1.0, f64::INFINITY, DVec3::ZERO), |s| (s.rod, s.t, s.p));
        let shape = at.map(|s| s.shape);
        let Material::Light { color, kind } = &self.mats[&m] else {
            return (DVec3::ZERO, false);
        };
        let distglow = matches!(kind, LightKind::Glow(rad) if *rad >= -FTINY && t > *rad);
        if r.flags & (AMBIENT | SPECULAR) != 0 && !(r.flags & SHADOW != 0 || rod < 0.0 || distglow)
        {
            return (DVec3::ZERO, true);
        }
        // A shadow ray is aimed at one source object: meeting another emitter, even one
        // of the same material, it is stopped (as Radiance compares the object hit with
        // the source's object), unless that emitter is an illum it may pass. An illum
        // does not pass a ray aimed at another illum or glow when met from its front
        // (that would count the light twice), except a ray relayed toward a virtual source.
        let own_source = r.src.is_none_or(|s| self.sources[s].prim == prim);
        if !own_source {
            let blocked = match kind {
                LightKind::Illum(_) => {
                    let s = &self.sources[r.src.expect("aimed ray")];
                    !matches!(s.geom, SourceGeom::Virtual { .. })
                        && rod > 0.0
                        && matches!(
                            self.mats[&s.mat],
                            Material::Light {
                                kind: LightKind::Illum(_) | LightKind::Glow(_),
                                ..
                            }
                        )
                }
                _ => true,
            };
            if blocked {
                return (DVec3::ZERO, true);
            }
        }
        if let LightKind::Illum(alt) = kind {
            // An illum is a source only for its own shadow rays; any other ray (a view
            // ray, or a shadow ray toward another source such as the sun through the
            // window it stands in) meets its alternate material.
            if r.src.is_none() || !own_source {
                if let Some(s) = at {
                    return match alt {
                        Some(a) => self.shade(r, *a, s, cx),
                        None => (self.pass(r.clone(), s.shape, s.p, s.t, cx), false),
                    };
                }
            }
        }
        if rod < 0.0 {
            return (DVec3::ZERO, false);
        }
        if let LightKind::Spot(cosang, aim, _) = kind {
            if (-r.dir).dot(*aim) < *cosang {
                return (DVec3::ZERO, false);
            }
        }
        let normal = match shape {
            Some(s) => self.accel.shapes[s].normal(p),
            None => -r.dir,
        };
        let q = PatternInput {
            dir: r.dir,
            point: p,
            normal,
            dist: t,
        };
        (*color * self.pattern(m, &q), false)
    }

    /// Product of the patterns on material `m` for a ray going along `dir`.
    pub(super) fn pattern(&self, m: usize, q: &PatternInput) -> DVec3 {
        match self.patterns.get(&m) {
            None => DVec3::ONE,
            Some(ps) => ps.iter().fold(DVec3::ONE, |acc, p| acc * p.eval(q)),
        }
    }
}
