//! Support for `sandslope plan`: raster readers and writers, route writers and the figure.

pub mod figure;
pub mod raster;
pub mod writers;
