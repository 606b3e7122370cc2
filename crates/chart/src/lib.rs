//! fenestra-chart: log–log line charts written as SVG text — error against run time, with
//! guides (a 1/√time slope through a series, horizontal limits) and a legend beside the
//! plot so that no text overlaps the data. Deterministic output, no plotting dependency.

pub mod axis;
pub mod plan;
pub mod raster;
pub mod svg;
pub mod tone;

/// One line of points.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend text.
    pub name: String,
    /// (x, y) points, both positive (log axes); drawn in the given order.
    pub points: Vec<(f64, f64)>,
    /// Draw a 1/√x guide through the series' first point (error ∝ 1/√samples, time ∝ samples).
    pub sqrt_guide: bool,
}

/// A horizontal line across the plot (e.g. a limit no sampling removes).
#[derive(Debug, Clone)]
pub struct Level {
    /// y value.
    pub y: f64,
    /// Legend text.
    pub name: String,
}

/// A chart: title, axis labels with units, series and levels.
#[derive(Debug, Clone, Default)]
pub struct Chart {
    /// Title above the plot.
    pub title: String,
    /// x-axis label (with its unit).
    pub x_label: String,
    /// y-axis label (with its unit).
    pub y_label: String,
    /// The lines.
    pub series: Vec<Series>,
    /// Horizontal lines.
    pub levels: Vec<Level>,
}
