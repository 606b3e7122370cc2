//! The Reinhart patch basis against reinhart.cal bins computed by the oracle's rcalc.

mod common;

use fenestra_sky::patches::Reinhart;

#[test]
fn direction_to_patch_matches_reinhart_cal() {
    for mf in [1usize, 2, 4] {
        let text = std::fs::read_to_string(common::fixture(&format!("sky/reinhart{mf}_bins.tsv")))
            .unwrap();
        let basis = Reinhart::new(mf);
        let mut n = 0;
        let mut bad = Vec::new();
        for line in text.lines().filter(|l| !l.starts_with('#')) {
            let f: Vec<&str> = line.split('\t').collect();
            let d = [
                f[1].parse::<f64>().unwrap(),
                f[2].parse::<f64>().unwrap(),
                f[3].parse::<f64>().unwrap(),
            ];
            let want: usize = f[5].parse().unwrap();
            let nbins: usize = f[6].parse().unwrap();
            assert_eq!(basis.len(), nbins, "MF {mf}: Nrbins");
            let got = basis.patch_of(d);
            if got != want {
                bad.push((f[0].to_string(), f[4].to_string(), want, got));
            }
            // reinhartb.cal (oracle library version): 0-based sky bins, -1 for the ground
            let want_b: i64 = f[7].parse().unwrap();
            let got_b = basis.sky_index_b(d).map_or(-1, |v| v as i64);
            if got_b != want_b {
                bad.push((
                    f[0].to_string(),
                    format!("{} (reinhartb)", f[4]),
                    want_b as usize,
                    got_b as usize,
                ));
            }
            assert_eq!(f[8].parse::<usize>().unwrap(), basis.sky_patches());
            n += 1;
        }
        // Every direction, including those exactly on boundaries (kinds 3, 6) and in
        // reinhart.cal's 1e-4° wrap zone (kind 12), must bin as reinhart.cal does.
        assert!(
            bad.is_empty(),
            "MF {mf}: {} of {n} differ: {:?}",
            bad.len(),
            &bad[..bad.len().min(10)]
        );
    }
}
