//! Annual daylight metrics per sensor over occupied hours — daylight autonomy (share of
//! hours at or above a threshold), useful daylight illuminance (share within a range), mean
//! illuminance — and how far each can move within the results' standard errors.
//!
//! The band of a metric is what it becomes when every hour's illuminance is moved by up to
//! `z` standard errors in the direction that lowers (or raises) it: the hours whose test
//! could flip are those within `z·σ` of a threshold. Errors of different hours are not
//! independent (every hour is a product of the same matrices), so this is a range the
//! metric can move within, not a confidence interval of a sum of independent flips.

/// Thresholds of the metrics, in lux, and the width of the band in standard errors.
#[derive(Debug, Clone, Copy)]
pub struct Thresholds {
    /// Daylight autonomy: hours with at least this illuminance (300).
    pub da: f64,
    /// Useful daylight illuminance: lower end of the range (100).
    pub udi_low: f64,
    /// Useful daylight illuminance: upper end of the range (2000).
    pub udi_high: f64,
    /// Half-width of the band in standard errors (2).
    pub z: f64,
}

impl Default for Thresholds {
    fn default() -> Self {
        Thresholds {
            da: 300.0,
            udi_low: 100.0,
            udi_high: 2000.0,
            z: 2.0,
        }
    }
}

/// How far a sensor's metrics can move within `z` standard errors of every hour.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Band {
    /// Daylight autonomy with every hour lowered by zσ, and raised by zσ.
    pub da: (f64, f64),
    /// Useful daylight illuminance: hours certainly within the range, and possibly within.
    pub udi: (f64, f64),
    /// Share of occupied hours whose daylight-autonomy test could flip.
    pub da_flip: f64,
    /// Share of occupied hours whose useful-daylight test could flip.
    pub udi_flip: f64,
    /// Standard error of the mean illuminance, taking the hours' errors as fully correlated
    /// (an upper bound: the mean of the hours' standard errors).
    pub mean_se: f64,
}

/// A sensor's metrics (shares as fractions 0–1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorMetrics {
    /// Occupied hours counted.
    pub hours: usize,
    /// Daylight autonomy.
    pub da: f64,
    /// Useful daylight illuminance.
    pub udi: f64,
    /// Mean illuminance over occupied hours, lux.
    pub mean: f64,
    /// The band, when standard errors are known.
    pub band: Option<Band>,
}

/// The metrics of one sensor: `lux[t]` (and `sd[t]`, its standard error) for hour t,
/// counted where `occupied[t]`.
pub fn sensor(
    lux: &[f64],
    sd: Option<&[f64]>,
    occupied: &[bool],
    th: &Thresholds,
) -> SensorMetrics {
    let (mut hours, mut da, mut udi, mut sum) = (0usize, 0usize, 0usize, 0.0f64);
    let (mut da_lo, mut da_hi, mut udi_lo, mut udi_hi, mut se_sum) = (0usize, 0, 0, 0, 0.0f64);
    let within = |e: f64| e >= th.udi_low && e <= th.udi_high;
    for (t, &e) in lux.iter().enumerate() {
        if !occupied.get(t).copied().unwrap_or(false) {
            continue;
        }
        hours += 1;
        sum += e;
        da += (e >= th.da) as usize;
        udi += within(e) as usize;
        if let Some(sd) = sd {
            let d = th.z * sd[t];
            se_sum += sd[t];
            da_lo += (e - d >= th.da) as usize;
            da_hi += (e + d >= th.da) as usize;
            // certainly within: the whole interval inside; possibly: the interval meets it
            udi_lo += (e - d >= th.udi_low && e + d <= th.udi_high) as usize;
            udi_hi += (e + d >= th.udi_low && e - d <= th.udi_high) as usize;
        }
    }
    let n = hours.max(1) as f64;
    SensorMetrics {
        hours,
        da: da as f64 / n,
        udi: udi as f64 / n,
        mean: sum / n,
        band: sd.map(|_| Band {
            da: (da_lo as f64 / n, da_hi as f64 / n),
            udi: (udi_lo as f64 / n, udi_hi as f64 / n),
            da_flip: (da_hi - da_lo) as f64 / n,
            udi_flip: (udi_hi - udi_lo) as f64 / n,
            mean_se: se_sum / n,
        }),
    }
}

/// Spatial daylight autonomy: the share of sensors whose daylight autonomy reaches
/// `share` (0.5 for sDA300/50%), and its band (sensors certainly and possibly reaching it).
pub fn spatial(sensors: &[SensorMetrics], share: f64) -> (f64, Option<(f64, f64)>) {
    let n = sensors.len().max(1) as f64;
    let count = |f: &dyn Fn(&SensorMetrics) -> f64| {
        sensors.iter().filter(|s| f(s) >= share).count() as f64 / n
    };
    let sda = count(&|s| s.da);
    let band = sensors.iter().all(|s| s.band.is_some()).then(|| {
        (
            count(&|s| s.band.map_or(0.0, |b| b.da.0)),
            count(&|s| s.band.map_or(0.0, |b| b.da.1)),
        )
    });
    (sda, band)
}

/// A room's figures over its sensors.
#[derive(Debug, Clone, PartialEq)]
pub struct Room {
    /// Spatial daylight autonomy ([`spatial`]).
    pub sda: f64,
    /// Its band, when every sensor has one.
    pub sda_band: Option<(f64, f64)>,
    /// The sensors' mean daylight autonomy.
    pub mean_da: f64,
    /// With standard errors: the means of the sensors' DA band ends and of the share of
    /// hours that could flip.
    pub da_band: Option<(f64, f64, f64)>,
}

/// The room's figures: sDA for `share` with its band, the mean DA and, `with_errors`, the
/// mean DA band and flip share (sensors without a band count as zero, over all sensors).
pub fn room(sensors: &[SensorMetrics], share: f64, with_errors: bool) -> Room {
    let (sda, sda_band) = spatial(sensors, share);
    let n = sensors.len().max(1) as f64;
    let mean = |f: &dyn Fn(&Band) -> f64| {
        sensors
            .iter()
            .filter_map(|s| s.band)
            .map(|b| f(&b))
            .sum::<f64>()
            / n
    };
    Room {
        sda,
        sda_band,
        mean_da: sensors.iter().map(|s| s.da).sum::<f64>() / n,
        da_band: with_errors.then(|| (mean(&|b| b.da.0), mean(&|b| b.da.1), mean(&|b| b.da_flip))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn room_figures_average_over_all_sensors() {
        let th = Thresholds::default();
        let occ = [true; 4];
        // DA 1.0 and 0.25 (300 lux threshold)
        let a = sensor(&[400.0, 500.0, 600.0, 700.0], None, &occ, &th);
        let b = sensor(&[100.0, 200.0, 250.0, 350.0], None, &occ, &th);
        let r = room(&[a, b], 0.5, false);
        assert_eq!((r.sda, r.mean_da), (0.5, 0.625));
        assert!(r.sda_band.is_none() && r.da_band.is_none());
    }

    #[test]
    fn hand_computed_sensor() {
        // 5 hours, the last unoccupied: 50, 280, 320, 2500, (900)
        let lux = [50.0, 280.0, 320.0, 2500.0, 900.0];
        let occ = [true, true, true, true, false];
        let th = Thresholds::default();
        let m = sensor(&lux, None, &occ, &th);
        assert_eq!(m.hours, 4);
        assert_eq!(m.da, 0.5); // 320, 2500
        assert_eq!(m.udi, 0.5); // 280, 320
        assert_eq!(m.mean, (50.0 + 280.0 + 320.0 + 2500.0) / 4.0);
        assert!(m.band.is_none());
        // σ = 15 everywhere, z = 2 (±30): 280 and 320 can flip the DA test; 50 (band 20–80)
        // cannot reach 100; 2500 (2470–2530) cannot reach 2000
        let sd = [15.0; 5];
        let b = sensor(&lux, Some(&sd), &occ, &th).band.unwrap();
        assert_eq!(b.da, (0.25, 0.75));
        assert_eq!(b.da_flip, 0.5);
        assert_eq!(b.udi, (0.5, 0.5));
        assert_eq!(b.udi_flip, 0.0);
        assert_eq!(b.mean_se, 15.0);
        // σ = 40: 50 (−30..130) may reach the UDI range; 280, 320 certainly inside it
        let sd = [40.0; 5];
        let b = sensor(&lux, Some(&sd), &occ, &th).band.unwrap();
        assert_eq!(b.udi, (0.5, 0.75));
        assert_eq!(b.udi_flip, 0.25);
    }

    #[test]
    fn spatial_autonomy_and_its_band() {
        let th = Thresholds::default();
        let occ = [true; 2];
        let s = [
            sensor(&[400.0, 400.0], Some(&[10.0, 10.0]), &occ, &th), // DA 1, certain
            sensor(&[310.0, 200.0], Some(&[10.0, 10.0]), &occ, &th), // DA 0.5, could be 0
            sensor(&[290.0, 100.0], Some(&[10.0, 10.0]), &occ, &th), // DA 0, could be 0.5
        ];
        let (sda, band) = spatial(&s, 0.5);
        assert!((sda - 2.0 / 3.0).abs() < 1e-12);
        let (lo, hi) = band.unwrap();
        assert!((lo - 1.0 / 3.0).abs() < 1e-12 && (hi - 1.0).abs() < 1e-12);
    }
}
