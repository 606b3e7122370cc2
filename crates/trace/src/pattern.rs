//! Patterns. Until fenestra's .cal engine is wired in, the two sky functions every
//! daylight workflow uses are evaluated natively (through fenestra-sky): `brightfunc`
//! with `skybr skybright.cal` (gensky) and `skybright perezlum.cal` (gendaylit).
//! Any other pattern is a clear error naming it.

use anyhow::{bail, Result};
use fenestra_scene::Scene;
use fenestra_sky::cie::SkyBright;
use fenestra_sky::skyvec::PerezLum;
use glam::DVec3;

/// A compiled pattern.
#[derive(Debug, Clone)]
pub enum Pattern {
    /// gensky's CIE sky (`skybright.cal`).
    Cie(SkyBright),
    /// gendaylit's Perez sky (`perezlum.cal`).
    Perez(PerezLum),
}

impl Pattern {
    /// Value for a ray travelling along unit `dir` (grey patterns give equal channels).
    pub fn eval(&self, dir: DVec3) -> DVec3 {
        let d = dir.to_array();
        DVec3::splat(match self {
            Pattern::Cie(s) => s.radiance(d),
            Pattern::Perez(p) => p.radiance(d),
        })
    }
}

/// Compiles pattern primitive `k` (used by material `user` for messages).
pub fn compile(scene: &Scene, k: usize, user: &str) -> Result<Pattern> {
    let q = &scene.prims[k];
    let file = |s: &str| s.rsplit('/').next().unwrap_or(s).to_string();
    if q.ptype == "brightfunc" && q.sargs.len() == 2 {
        let (func, cal) = (q.sargs[0].as_str(), file(&q.sargs[1]));
        if func == "skybr" && cal == "skybright.cal" {
            if let Some(s) = SkyBright::from_args(&q.rargs) {
                return Ok(Pattern::Cie(s));
            }
            bail!(
                "{}: brightfunc '{}': bad arguments for skybright.cal",
                q.loc,
                q.name
            );
        }
        if func == "skybright" && cal == "perezlum.cal" {
            if let Some(p) = PerezLum::from_args(&q.rargs) {
                return Ok(Pattern::Perez(p));
            }
            bail!(
                "{}: brightfunc '{}': perezlum.cal needs 10 real arguments",
                q.loc,
                q.name
            );
        }
    }
    bail!(
        "{}: {} '{}' (modifying '{user}'): fenestra's ray tracer evaluates only the sky patterns \
         'skybr skybright.cal' and 'skybright perezlum.cal' in this build; other patterns and textures are not supported",
        q.loc,
        q.ptype,
        q.name
    )
}
