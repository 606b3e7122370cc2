//! A run's budget, for `-v`: what it traced (rays by kind, time) and how well it knows
//! its output — the total of every modifier's values (in luminance units) with the
//! standard error of that total, from the rays' own totals (every covariance between bins
//! included; records are independent, so their variances add).

use fenestra_trace::{Effects, RayCounts};

use crate::engine::{Engine, Record};

/// Totals gathered as records are written.
#[derive(Debug, Clone, Default)]
pub struct Budget {
    /// Records written.
    pub records: u64,
    /// Per modifier: the sum of its values over bins and records (luminance units).
    pub totals: Vec<f64>,
    /// Per modifier: the variance of that sum (with `-E`; empty otherwise).
    pub variances: Vec<f64>,
}

impl Budget {
    /// Adds one written record.
    pub fn add(&mut self, engine: &Engine, rec: &Record) {
        let t = engine.modifier_totals(rec);
        if self.totals.len() != t.len() {
            self.totals = vec![0.0; t.len()];
        }
        for (a, b) in self.totals.iter_mut().zip(&t) {
            *a += b;
        }
        if let Some(se) = &rec.total_se {
            if self.variances.len() != se.len() {
                self.variances = vec![0.0; se.len()];
            }
            for (v, s) in self.variances.iter_mut().zip(se) {
                *v += s * s;
            }
        }
        self.records += 1;
    }

    /// The lines `-v` prints: effects, rays by kind and time, each modifier's total with
    /// its relative standard error (or how to get it).
    pub fn lines(
        &self,
        names: &[String],
        rays: RayCounts,
        seconds: f64,
        effects: &Effects,
    ) -> Vec<String> {
        let mut out: Vec<String> = effects
            .notes
            .iter()
            .map(|n| format!("effect: {n}"))
            .collect();
        out.push(format!(
            "{} records in {seconds:.2} s; rays traced: {rays}",
            self.records
        ));
        for (k, name) in names.iter().enumerate() {
            let total = self.totals.get(k).copied().unwrap_or(0.0);
            let se = match self.variances.get(k) {
                Some(v) if total != 0.0 => format!(
                    "standard error {:.3}% of it",
                    100.0 * v.sqrt() / total.abs()
                ),
                Some(v) => format!("standard error {:.3e}", v.sqrt()),
                None => "standard error not computed (give -E)".to_string(),
            };
            out.push(format!(
                "modifier {name}: total of every value {} (luminance weights 0.265 0.670 0.065), {se}",
                fenestra_cfmt::fmt_e(total, 6)
            ));
        }
        out
    }
}
