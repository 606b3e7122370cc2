//! The built-in function library: the 18 functions every calcomp program has, and the
//! optional extras of rcalc (`in`, Bessel and error functions) and of the renderers (`arg`).

/// A built-in function.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Builtin {
    /// `if(c, a, b)`: `a` when `c > 0`, else `b`.
    If,
    /// `select(n, a1, …)`: the `n`th argument (rounded); `select(0, …)` is the count.
    Select,
    /// One-argument math function.
    Math1(Math1),
    /// `atan2(y, x)`.
    Atan2,
    /// `max(a, …)`.
    Max,
    /// `min(a, …)`.
    Min,
    /// `rand(x)`: Radiance's deterministic hash in [0, 1).
    Rand,
    /// `jn(n, x)` Bessel function of the first kind.
    Jn,
    /// `yn(n, x)` Bessel function of the second kind.
    Yn,
    /// `in(n)`: input column `n` (rcalc); `in(0)` is the column count.
    In,
    /// `arg(n)`: the `n`th real argument of the current primitive; `arg(0)` is the count.
    Arg,
}

/// One-argument math functions.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Math1 {
    /// sqrt
    Sqrt,
    /// sin
    Sin,
    /// cos
    Cos,
    /// tan
    Tan,
    /// asin
    Asin,
    /// acos
    Acos,
    /// atan
    Atan,
    /// exp
    Exp,
    /// natural log
    Log,
    /// log10
    Log10,
    /// floor
    Floor,
    /// ceil
    Ceil,
    /// Bessel j0
    J0,
    /// Bessel j1
    J1,
    /// Bessel y0
    Y0,
    /// Bessel y1
    Y1,
    /// erf
    Erf,
    /// erfc
    Erfc,
}

mod libm {
    extern "C" {
        pub fn j0(x: f64) -> f64;
        pub fn j1(x: f64) -> f64;
        pub fn jn(n: i32, x: f64) -> f64;
        pub fn y0(x: f64) -> f64;
        pub fn y1(x: f64) -> f64;
        pub fn yn(n: i32, x: f64) -> f64;
        pub fn erf(x: f64) -> f64;
        pub fn erfc(x: f64) -> f64;
    }
}

impl Builtin {
    /// The fewest arguments a call takes.
    pub fn min_args(self) -> usize {
        match self {
            Builtin::If => 3,
            Builtin::Atan2 | Builtin::Jn | Builtin::Yn => 2,
            _ => 1,
        }
    }

    /// The name the language calls it by.
    pub fn name(self) -> &'static str {
        match self {
            Builtin::If => "if",
            Builtin::Select => "select",
            Builtin::Math1(m) => m.name(),
            Builtin::Atan2 => "atan2",
            Builtin::Max => "max",
            Builtin::Min => "min",
            Builtin::Rand => "rand",
            Builtin::Jn => "jn",
            Builtin::Yn => "yn",
            Builtin::In => "in",
            Builtin::Arg => "arg",
        }
    }
}

/// The NaN Radiance's rcalc prints as `-nan` for `acos`/`asin` outside [-1, 1].
const NEG_NAN: f64 = f64::from_bits(0xfff8_0000_0000_0000);

impl Math1 {
    /// The name the language calls it by.
    pub fn name(self) -> &'static str {
        match self {
            Math1::Sqrt => "sqrt",
            Math1::Sin => "sin",
            Math1::Cos => "cos",
            Math1::Tan => "tan",
            Math1::Asin => "asin",
            Math1::Acos => "acos",
            Math1::Atan => "atan",
            Math1::Exp => "exp",
            Math1::Log => "log",
            Math1::Log10 => "log10",
            Math1::Floor => "floor",
            Math1::Ceil => "ceil",
            Math1::J0 => "j0",
            Math1::J1 => "j1",
            Math1::Y0 => "y0",
            Math1::Y1 => "y1",
            Math1::Erf => "erf",
            Math1::Erfc => "erfc",
        }
    }

    /// Applies the function.
    #[inline]
    pub fn apply(self, x: f64) -> f64 {
        match self {
            Math1::Sqrt => x.sqrt(),
            Math1::Sin => x.sin(),
            Math1::Cos => x.cos(),
            Math1::Tan => x.tan(),
            Math1::Asin if x.abs() > 1.0 => NEG_NAN,
            Math1::Acos if x.abs() > 1.0 => NEG_NAN,
            Math1::Log10 if x < 0.0 => NEG_NAN,
            Math1::Asin => x.asin(),
            Math1::Acos => x.acos(),
            Math1::Atan => x.atan(),
            Math1::Exp => x.exp(),
            Math1::Log => x.ln(),
            Math1::Log10 => x.log10(),
            // the oracle's floor/ceil never return -0
            Math1::Floor => x.floor() + 0.0,
            Math1::Ceil => x.ceil() + 0.0,
            // SAFETY: plain C math functions of the system libm, pure on their argument.
            Math1::J0 => unsafe { libm::j0(x) },
            // SAFETY: as above.
            Math1::J1 => unsafe { libm::j1(x) },
            // SAFETY: as above.
            Math1::Y0 => unsafe { libm::y0(x) },
            // SAFETY: as above.
            Math1::Y1 => unsafe { libm::y1(x) },
            // SAFETY: as above.
            Math1::Erf => unsafe { libm::erf(x) },
            // SAFETY: as above.
            Math1::Erfc => unsafe { libm::erfc(x) },
        }
    }
}

/// `jn(n, x)` with `n` truncated to an integer as C does.
pub fn jn(n: f64, x: f64) -> f64 {
    // SAFETY: plain C math function.
    unsafe { libm::jn(n as i32, x) }
}

/// `yn(n, x)` with `n` truncated to an integer as C does.
pub fn yn(n: f64, x: f64) -> f64 {
    // SAFETY: plain C math function.
    unsafe { libm::yn(n as i32, x) }
}

/// `select`'s index: `(int)(x + .5)`, `None` for NaN, below −0.5 or from 2^31 on (an
/// error in Radiance).
#[inline]
pub fn select_index(x: f64) -> Option<usize> {
    if x.is_nan() || x < -0.5 || x + 0.5 >= 2147483648.0 {
        None
    } else {
        Some((x + 0.5) as i64 as usize)
    }
}

/// `in(x)` / `arg(x)` over `vals` (the input channels, the primitive's real arguments):
/// index `(int)(x + .5)`, 0 gives the count, 1 to the count the value; otherwise the
/// index as `Err` (`in` gives 0 there, `arg` raises an error).
#[inline]
pub fn in_arg_index(x: f64, vals: &[f64]) -> Result<f64, i64> {
    let i = (x + 0.5) as i64;
    if i == 0 {
        Ok(vals.len() as f64)
    } else if i > 0 && (i as usize) <= vals.len() {
        Ok(vals[i as usize - 1])
    } else {
        Err(i)
    }
}

/// Radiance's `rand(x)`: a deterministic hash of `x` into [0, 1).
#[inline]
#[allow(clippy::approx_constant)] // Radiance's truncated constants, kept for identical output
pub fn rand_hash(x: f64) -> f64 {
    let mut x = x * (1.0 / (1.0 + x * x) + 2.718_281_828_459_04);
    x += 0.785_398_163_397_447 - x.floor();
    x = 1e5 / x;
    x - x.floor()
}

/// Which optional groups of built-ins a program has.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Extras {
    /// rcalc/ev additions: `in`, `j0 j1 jn y0 y1 yn erf erfc`.
    pub rcalc: bool,
    /// renderer additions: `arg`, `erf`, `erfc`.
    pub render: bool,
}

/// Looks up a built-in by name (with the extras enabled), with its minimum argument count.
pub fn lookup(name: &str, extras: Extras) -> Option<(Builtin, usize)> {
    use Builtin as B;
    use Math1 as M;
    let math = [
        M::Sqrt,
        M::Sin,
        M::Cos,
        M::Tan,
        M::Asin,
        M::Acos,
        M::Atan,
        M::Exp,
        M::Log,
        M::Log10,
        M::Floor,
        M::Ceil,
        M::J0,
        M::J1,
        M::Y0,
        M::Y1,
        M::Erf,
        M::Erfc,
    ];
    let other = [
        B::If,
        B::Select,
        B::Atan2,
        B::Rand,
        B::Max,
        B::Min,
        B::In,
        B::Jn,
        B::Yn,
        B::Arg,
    ];
    let b = other
        .into_iter()
        .chain(math.map(B::Math1))
        .find(|b| b.name() == name)?;
    let enabled = match b {
        // rcalc/ev additions
        B::In | B::Jn | B::Yn | B::Math1(M::J0 | M::J1 | M::Y0 | M::Y1) => extras.rcalc,
        B::Math1(M::Erf | M::Erfc) => extras.rcalc || extras.render,
        // renderer additions
        B::Arg => extras.render,
        _ => true,
    };
    enabled.then_some((b, b.min_args()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rand_matches_radiance_values() {
        // Values printed by Radiance's rcalc with %.9g.
        assert_eq!(format!("{:.9}", rand_hash(0.5)), "0.234347013");
        assert_eq!(format!("{:.8}", rand_hash(1.0)), "0.35008306");
    }
}
