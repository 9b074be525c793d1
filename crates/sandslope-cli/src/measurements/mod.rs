//! Support for `sandslope fit`: reading a measurement manifest and its trial CSVs into the
//! library's plain arrays ([`reader`]) and drawing the force-measurement figure ([`figures`]).

pub mod figures;
pub mod reader;
