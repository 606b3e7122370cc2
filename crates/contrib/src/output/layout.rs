//! Which modifier bins go to which output stream, in command-line order.

use super::*;

/// One output stream: its destination and the (modifier, bin) values of each record.
#[derive(Debug, Clone)]
pub struct StreamPlan {
    /// Destination (`None`: standard output; `!cmd`: a command).
    pub name: Option<String>,
    /// Values of a record in order: (modifier index, bin).
    pub items: Vec<(usize, usize)>,
    /// `MODIFIER=` header value.
    pub modifier: Option<String>,
    /// `BIN=` header value.
    pub bin: Option<usize>,
    spec_has_mod: bool,
}

/// A modifier as far as outputs are concerned.
pub struct ModOut<'a> {
    /// Its name.
    pub name: &'a str,
    /// Its output spec (`None` = standard output).
    pub spec: Option<&'a Spec>,
    /// Its bin count.
    pub nbins: usize,
}

/// Works out the streams for the modifiers, in command-line order. `picture`: with
/// `-x -y` pictures, later modifiers sharing a `%d`-only spec move to the next unused
/// file number (as Radiance does).
pub fn plan(mods: &[ModOut], picture: bool) -> Vec<StreamPlan> {
    let mut streams: Vec<StreamPlan> = Vec::new();
    let mut used: Vec<(String, usize)> = Vec::new();
    let add = |streams: &mut Vec<StreamPlan>,
               name: Option<String>,
               item: (usize, usize),
               modname: &str,
               bin: Option<usize>,
               has_mod: bool| {
        match streams.iter_mut().find(|s| s.name == name) {
            Some(s) => s.items.push(item),
            None => streams.push(StreamPlan {
                name,
                items: vec![item],
                modifier: if has_mod {
                    Some(modname.to_string())
                } else {
                    None
                },
                bin,
                spec_has_mod: has_mod,
            }),
        }
    };
    for (m, md) in mods.iter().enumerate() {
        match md.spec {
            None => {
                for b in 0..md.nbins {
                    add(&mut streams, None, (m, b), md.name, None, false);
                }
            }
            Some(sp) => {
                let shift = if sp.has_bin && !sp.has_mod && picture {
                    match used.iter_mut().find(|(t, _)| *t == sp.text) {
                        Some((_, n)) => {
                            let s = *n;
                            *n += md.nbins;
                            s
                        }
                        None => {
                            used.push((sp.text.clone(), md.nbins));
                            0
                        }
                    }
                } else {
                    0
                };
                for b in 0..md.nbins {
                    let fileno = b + shift;
                    let name = sp.expand(md.name, fileno);
                    let bin = if sp.has_bin { Some(fileno) } else { None };
                    add(&mut streams, Some(name), (m, b), md.name, bin, sp.has_mod);
                }
            }
        }
    }
    for s in &mut streams {
        if s.items.len() == 1 && !s.spec_has_mod {
            s.modifier = Some(mods[s.items[0].0].name.to_string());
        }
    }
    streams
}
