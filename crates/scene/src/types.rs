//! Primitive types Radiance defines and their argument-count rules.

/// How many arguments of one kind a type takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Count {
    /// Exactly n.
    Exact(usize),
    /// One of the listed values.
    OneOf(&'static [usize]),
    /// At least n.
    AtLeast(usize),
    /// A multiple of `step`, at least `min`.
    Multiple { step: usize, min: usize },
    /// Anything.
    Any,
}

impl Count {
    /// Whether `n` arguments satisfy the rule.
    pub fn accepts(self, n: usize) -> bool {
        match self {
            Count::Exact(k) => n == k,
            Count::OneOf(ks) => ks.contains(&n),
            Count::AtLeast(k) => n >= k,
            Count::Multiple { step, min } => n >= min && n % step == 0,
            Count::Any => true,
        }
    }

    fn describe(self) -> String {
        match self {
            Count::Exact(k) => format!("{k}"),
            Count::OneOf(ks) => {
                let v: Vec<String> = ks.iter().map(|k| k.to_string()).collect();
                v.join(" or ")
            }
            Count::AtLeast(k) => format!("at least {k}"),
            Count::Multiple { step, min } => format!("a multiple of {step} (at least {min})"),
            Count::Any => "any number of".into(),
        }
    }
}

/// The argument rule of one primitive type.
#[derive(Debug, Clone, Copy)]
pub struct TypeRule {
    /// Type name.
    pub name: &'static str,
    /// True for geometry.
    pub surface: bool,
    /// String-argument count.
    pub strings: Count,
    /// Real-argument count.
    pub reals: Count,
    /// What the arguments are (for messages).
    pub args: &'static str,
}

const fn r(
    name: &'static str,
    surface: bool,
    strings: Count,
    reals: Count,
    args: &'static str,
) -> TypeRule {
    TypeRule {
        name,
        surface,
        strings,
        reals,
        args,
    }
}

use Count::*;

/// Every primitive type Radiance defines.
pub const RULES: &[TypeRule] = &[
    // geometry
    r("source", true, Exact(0), Exact(4), "reals: dx dy dz angle"),
    r("sphere", true, Exact(0), Exact(4), "reals: cx cy cz radius"),
    r("bubble", true, Exact(0), Exact(4), "reals: cx cy cz radius"),
    r("polygon", true, Exact(0), Multiple { step: 3, min: 9 }, "reals: x y z per vertex, at least 3 vertices"),
    r("cone", true, Exact(0), Exact(8), "reals: x0 y0 z0 x1 y1 z1 r0 r1"),
    r("cup", true, Exact(0), Exact(8), "reals: x0 y0 z0 x1 y1 z1 r0 r1"),
    r("cylinder", true, Exact(0), Exact(7), "reals: x0 y0 z0 x1 y1 z1 radius"),
    r("tube", true, Exact(0), Exact(7), "reals: x0 y0 z0 x1 y1 z1 radius"),
    r("ring", true, Exact(0), Exact(8), "reals: cx cy cz nx ny nz r0 r1"),
    r("instance", true, AtLeast(1), Exact(0), "strings: octree [transform]"),
    r("mesh", true, AtLeast(1), Exact(0), "strings: meshfile [transform]"),
    // light sources
    r("light", false, Exact(0), Exact(3), "reals: red green blue"),
    r("glow", false, Exact(0), Exact(4), "reals: red green blue maxrad"),
    r("illum", false, OneOf(&[0, 1]), Exact(3), "strings: [altmat]; reals: red green blue"),
    r("spotlight", false, Exact(0), Exact(7), "reals: red green blue angle dx dy dz"),
    // materials
    r("plastic", false, Exact(0), Exact(5), "reals: red green blue spec rough"),
    r("metal", false, Exact(0), Exact(5), "reals: red green blue spec rough"),
    r("trans", false, Exact(0), Exact(7), "reals: red green blue spec rough trans tspec"),
    r("plastic2", false, AtLeast(4), Exact(6), "strings: ux uy uz funcfile [transform]; reals: red green blue spec urough vrough"),
    r("metal2", false, AtLeast(4), Exact(6), "strings: ux uy uz funcfile [transform]; reals: red green blue spec urough vrough"),
    r("trans2", false, AtLeast(4), Exact(8), "strings: ux uy uz funcfile [transform]; reals: red green blue spec urough vrough trans tspec"),
    r("mirror", false, OneOf(&[0, 1]), Exact(3), "strings: [altmat]; reals: red green blue"),
    r("dielectric", false, Exact(0), Exact(5), "reals: rtn gtn btn n hc"),
    r("interface", false, Exact(0), Exact(8), "reals: rtn1 gtn1 btn1 n1 rtn2 gtn2 btn2 n2"),
    r("glass", false, Exact(0), OneOf(&[3, 4]), "reals: rtn gtn btn [n]"),
    r("BSDF", false, AtLeast(6), OneOf(&[0, 3, 6, 9]), "strings: thick BSDFfile ux uy uz funcfile [transform]; reals: 0, 3, 6 or 9 diffuse colours"),
    r("aBSDF", false, AtLeast(5), OneOf(&[0, 3, 6, 9]), "strings: BSDFfile ux uy uz funcfile [transform]; reals: 0, 3, 6 or 9 diffuse colours"),
    r("plasfunc", false, AtLeast(2), AtLeast(5), "strings: refl funcfile [transform]; reals: red green blue spec rough [A…]"),
    r("metfunc", false, AtLeast(2), AtLeast(5), "strings: refl funcfile [transform]; reals: red green blue spec rough [A…]"),
    r("transfunc", false, AtLeast(2), AtLeast(7), "strings: refl funcfile [transform]; reals: red green blue spec rough trans tspec [A…]"),
    r("BRTDfunc", false, AtLeast(10), AtLeast(9), "strings: rrefl grefl brefl rtrns gtrns btrns rbrtd gbrtd bbrtd funcfile [transform]; reals: 9 diffuse colours [A…]"),
    r("plasdata", false, AtLeast(3), AtLeast(5), "strings: func datafile funcfile x1 … [transform]; reals: red green blue spec rough [A…]"),
    r("metdata", false, AtLeast(3), AtLeast(5), "strings: func datafile funcfile x1 … [transform]; reals: red green blue spec rough [A…]"),
    r("transdata", false, AtLeast(3), AtLeast(7), "strings: func datafile funcfile x1 … [transform]; reals: red green blue spec rough trans tspec [A…]"),
    r("ashik2", false, AtLeast(4), Exact(8), "strings: ux uy uz funcfile [transform]; reals: red green blue sred sgrn sblu u-exp v-exp"),
    r("WGMDfunc", false, AtLeast(13), AtLeast(9), "strings: rs_mod rs ur vr td_mod ts_mod ts ut vt ux uy uz funcfile [transform]"),
    r("antimatter", false, AtLeast(1), Exact(0), "strings: mod1 … modN"),
    r("mist", false, Any, OneOf(&[3, 6, 7]), "strings: [sources …]; reals: rext gext bext [ralb galb balb [g]]"),
    r("prism1", false, AtLeast(5), Any, "strings: dx dy dz funcfile [transform]"),
    r("prism2", false, AtLeast(9), Any, "strings: coef1 dx1 dy1 dz1 coef2 dx2 dy2 dz2 funcfile [transform]"),
    // patterns, textures, mixtures
    r("brightfunc", false, AtLeast(2), Any, "strings: refl funcfile [transform]"),
    r("colorfunc", false, AtLeast(4), Any, "strings: red green blue funcfile [transform]"),
    r("brightdata", false, AtLeast(3), Any, "strings: func datafile funcfile x1 … [transform]"),
    r("colordata", false, AtLeast(7), Any, "strings: rfunc gfunc bfunc rdata gdata bdata funcfile x1 … [transform]"),
    r("colorpict", false, AtLeast(7), Any, "strings: rfunc gfunc bfunc pictfile funcfile u v [transform]"),
    r("brighttext", false, AtLeast(2), Any, "strings: fontfile textfile [transform]"),
    r("colortext", false, AtLeast(2), Any, "strings: fontfile textfile [transform]"),
    r("texfunc", false, AtLeast(4), Any, "strings: xpert ypert zpert funcfile [transform]"),
    r("texdata", false, AtLeast(8), Any, "strings: xfunc yfunc zfunc xdata ydata zdata funcfile x1 … [transform]"),
    r("mixfunc", false, AtLeast(4), Any, "strings: foreground background vname funcfile [transform]"),
    r("mixdata", false, AtLeast(5), Any, "strings: foreground background func datafile funcfile x1 … [transform]"),
    r("mixpict", false, AtLeast(7), Any, "strings: foreground background func pictfile funcfile u v [transform]"),
    r("mixtext", false, AtLeast(4), Any, "strings: foreground background fontfile textfile [transform]"),
    r("spectrum", false, Exact(0), AtLeast(5), "reals: nmA nmB s1 s2 s3 …"),
    r("specfile", false, Exact(1), Any, "strings: datafile"),
    r("specfunc", false, AtLeast(2), AtLeast(2), "strings: func funcfile [transform]; reals: nmA nmB …"),
    r("specdata", false, AtLeast(3), Any, "strings: func datafile funcfile x1 … [transform]"),
    r("specpict", false, AtLeast(5), Any, "strings: func pictfile funcfile u v [transform]"),
];

/// The rule for `ptype`, if Radiance defines that type.
pub fn rule(ptype: &str) -> Option<&'static TypeRule> {
    RULES.iter().find(|r| r.name == ptype)
}

/// True when `ptype` is a geometric primitive (its identifier is never a modifier).
pub fn is_surface(ptype: &str) -> bool {
    rule(ptype).is_some_and(|r| r.surface)
}

/// Checks a primitive's argument counts; the error says what was expected.
pub fn check(ptype: &str, nstrings: usize, nints: usize, nreals: usize) -> Result<(), String> {
    let Some(rule) = rule(ptype) else {
        return Err(format!("unknown primitive type '{ptype}'"));
    };
    if nints != 0 {
        return Err(format!(
            "{ptype} takes no integer arguments (the middle count must be 0), got {nints}"
        ));
    }
    if !rule.strings.accepts(nstrings) {
        return Err(format!(
            "{ptype} takes {} string arguments, got {nstrings} ({})",
            rule.strings.describe(),
            rule.args
        ));
    }
    if !rule.reals.accepts(nreals) {
        return Err(format!(
            "{ptype} takes {} real arguments, got {nreals} ({})",
            rule.reals.describe(),
            rule.args
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts() {
        assert!(check("polygon", 0, 0, 12).is_ok());
        assert!(check("polygon", 0, 0, 10)
            .unwrap_err()
            .contains("multiple of 3"));
        assert!(check("polygon", 0, 0, 6).is_err());
        assert!(check("glass", 0, 0, 4).is_ok());
        assert!(check("glass", 0, 0, 5).is_err());
        assert!(check("plastic", 0, 1, 5).unwrap_err().contains("integer"));
        assert!(check("BSDF", 6, 0, 3).is_ok());
        assert!(check("BSDF", 5, 0, 0).is_err());
        assert!(check("blob", 0, 0, 0).unwrap_err().contains("unknown"));
    }
}
