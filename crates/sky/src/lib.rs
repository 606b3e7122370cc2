//! fenestra-sky: solar position, CIE skies (gensky), the Perez all-weather sky
//! (gendaymtx, gendaylit), the Reinhart patch basis and sky vectors (genskyvec).

pub mod cie;
pub mod daylit;
pub mod daymtx;
pub mod patches;
pub mod perez;
pub mod skyvec;
pub mod solar;
pub mod weather;
