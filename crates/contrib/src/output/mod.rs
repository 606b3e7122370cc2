//! Output destinations of the contribution tracer: `-o` specs with `%s`/`%d` fields,
//! the streams they make (which modifier bins go where), headers, and record writing.

mod header;
mod layout;
mod recover;
mod spec;
mod stream;

pub use header::{header_text, HeaderInfo};
pub use layout::{plan, ModOut, StreamPlan};
use recover::PartialFile;
pub use recover::{check_files, examine_partial, partial_path, record_size, reload_sums, Partial};
pub use spec::{format_of, Format, Spec};
pub use stream::Stream;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spec_fields() {
        let s = Spec::parse("out/%s_%03d.dat").unwrap();
        assert!(s.has_mod && s.has_bin);
        assert_eq!(s.expand("sky", 7), "out/sky_007.dat");
        assert!(Spec::parse("a%f").is_err());
        assert!(Spec::parse("a%d%d").is_err());
        assert_eq!(Spec::parse("v%x").unwrap().expand("m", 255), "vff");
    }

    #[test]
    fn picture_bins_shift() {
        let sp = Spec::parse("v%03d.hdr").unwrap();
        let mods = [
            ModOut {
                name: "g",
                spec: Some(&sp),
                nbins: 1,
            },
            ModOut {
                name: "s",
                spec: Some(&sp),
                nbins: 3,
            },
        ];
        let p = plan(&mods, true);
        assert_eq!(p.len(), 4);
        assert_eq!(p[3].name.as_deref(), Some("v003.hdr"));
        assert_eq!(p[3].modifier.as_deref(), Some("s"));
        let p = plan(&mods, false);
        assert_eq!(p.len(), 3);
        assert_eq!(p[0].items, vec![(0, 0), (1, 0)]);
        assert_eq!(p[0].modifier, None);
    }
}
