//! Plots of a run (plotters; every plot as PNG and SVG under `plots/`):
//! - `<scenario>-errors`: one panel per plotted metric of the table (`E_theta`, `E_phi`, `e_area`,
//!   `e_length`), side by side, a bar per method;
//! - `<scenario>-timings`: stacked precompute / handle bind / solve time per method;
//! - `<scenario>-convergence`: step size, `E_theta` and `E_phi` per iteration, one line per method
//!   (the scale-aware paper's Fig. 6);
//! - `scaling`: log-log per-iteration time against vertex count over the resolution sweeps
//!   (scenarios named `*-sweep-*`), one line per method;
//! - `table1`: HIRM's Table 1 as a chart, handle-set update time against the number of handles,
//!   `hirm`'s `t_h` and the `isolines` rebuild, per `*-handles` scenario;
//! - `<scenario>-pareto`, for a scenario with sweep points ([`crate::sweep`]): quality against time
//!   ([`crate::pareto`]), a row per measure (E_theta, E_phi, e_area), a column per time (per edit;
//!   with the precompute), each sweep's points joined in parameter order, the front across all
//!   methods as a black staircase, suspect points crossed.
//!
//! Every file is drawn to a temporary name and renamed when complete, so a failure leaves no
//! half-written plot.

use std::path::{Path, PathBuf};

use plotters::coord::ranged1d::ValueFormatter;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::document::{Image, ImageGroup};
use crate::error::HarnessError;
use crate::metrics::{MetricSpec, METRICS};
use crate::record::CaseResult;

/// Pixel size of every plot but the errors plot.
const SIZE: (u32, u32) = (960, 540);
/// Pixel size of the errors plot (one panel per plotted metric, side by side).
const ERRORS_SIZE: (u32, u32) = (1500, 560);
/// Pixel size of the dataset's ECDF plot (two by two measures).
const ECDF_SIZE: (u32, u32) = (1500, 1600);
/// Pixel size of the quality–time plot (three measures by two time axes).
const PARETO_SIZE: (u32, u32) = (1600, 1950);
/// Three panels side by side, each with a legend of (series, method) lines.
const SIZE_SERIES_SIZE: (u32, u32) = (1800, 640);

/// Method colours, fixed by registry order so a method has the same colour in every plot; the other
/// methods (external, peers) of `cases` follow in their order there, which is the catalog's in every
/// scenario they run on.
fn method_color(method: &str, cases: &[&CaseResult]) -> RGBColor {
    const PALETTE: [RGBColor; 15] = [
        RGBColor(31, 119, 180),
        RGBColor(255, 127, 14),
        RGBColor(44, 160, 44),
        RGBColor(214, 39, 40),
        RGBColor(148, 103, 189),
        RGBColor(140, 86, 75),
        RGBColor(227, 119, 194),
        RGBColor(127, 127, 127),
        RGBColor(188, 189, 34),
        RGBColor(23, 190, 207),
        RGBColor(0, 0, 0),
        RGBColor(128, 0, 0),
        RGBColor(0, 90, 90),
        RGBColor(90, 60, 0),
        RGBColor(70, 0, 130),
    ];
    let builtin = methods::registry::method_names();
    let index = builtin.iter().position(|m| *m == method).unwrap_or_else(|| {
        let mut others: Vec<&str> = Vec::new();
        for c in cases {
            if !builtin.contains(&c.method.as_str()) && !others.contains(&c.method.as_str()) {
                others.push(&c.method);
            }
        }
        builtin.len() + others.iter().position(|m| *m == method).unwrap_or(0)
    });
    PALETTE[index % PALETTE.len()]
}

/// Write every plot of `results` under `dir/plots/`, each as PNG and SVG; returns the PNGs, their
/// paths relative to `dir`, in the page's groups.
pub fn write_plots(dir: &Path, results: &[CaseResult]) -> Result<Vec<Image>, HarnessError> {
    crate::report::fonts::register_sans_serif()?;
    let plot_dir = dir.join("plots");
    std::fs::create_dir_all(&plot_dir).map_err(|error| HarnessError::Io { path: plot_dir.clone(), error })?;
    let mut written = scenario_plots(dir, results)?;
    let sweeps: Vec<&CaseResult> =
        results.iter().filter(|r| r.scenario.contains("-sweep-") && !r.status.is_failed()).collect();
    if !sweeps.is_empty() {
        written.push(save(dir, "scaling", ImageGroup::Plot, &Plot::Scaling(&sweeps))?);
    }
    let handle_scenarios: Vec<&CaseResult> = results
        .iter()
        .filter(|r| r.scenario.ends_with("-handles") && methods::registry::table1_side(&r.method).is_some())
        .collect();
    if !handle_scenarios.is_empty() {
        written.push(save(dir, "table1", ImageGroup::Plot, &Plot::Table1(&handle_scenarios))?);
    }
    let dataset = crate::report::dataset::dataset_cases(results);
    if !dataset.is_empty() {
        written.push(save(dir, "dataset-ecdf", ImageGroup::Dataset, &Plot::DatasetEcdf(&dataset))?);
        written.push(save(dir, "dataset-cost", ImageGroup::Dataset, &Plot::DatasetCost(&dataset))?);
    }
    let series: Vec<&CaseResult> =
        crate::report::size_series::series_cases(results).into_values().flatten().collect();
    if !series.is_empty() {
        written.push(save(dir, "size-series", ImageGroup::SizeSeries, &Plot::SizeSeries(&series))?);
    }
    Ok(written)
}

/// The plots of each test that is not a collection's (those are summed up by the dataset plots):
/// errors, timings, convergence, and quality against time when it has sweep points.
fn scenario_plots(dir: &Path, results: &[CaseResult]) -> Result<Vec<Image>, HarnessError> {
    let mut scenarios: Vec<&str> = Vec::new();
    for r in results {
        if !scenarios.contains(&r.scenario.as_str()) {
            scenarios.push(&r.scenario);
        }
    }
    let swept = crate::report::quality_time::swept_scenarios(results);
    scenarios.retain(|s| results.iter().any(|r| r.scenario == *s && r.member.is_none()));
    let mut written = Vec::new();
    for scenario in scenarios {
        let cases: Vec<&CaseResult> = results.iter().filter(|r| r.scenario == scenario).collect();
        let plot = |stem: &str, plot: Plot| save(dir, &format!("{scenario}-{stem}"), ImageGroup::Plot, &plot);
        written.push(plot("errors", Plot::Errors(scenario, &cases))?);
        written.push(plot("timings", Plot::Timings(scenario, &cases))?);
        written.push(plot("convergence", Plot::Convergence(scenario, &cases))?);
        if swept.contains(&scenario) {
            let group = ImageGroup::QualityTime(scenario.to_string());
            let mut pareto =
                save(dir, &format!("{scenario}-pareto"), group, &Plot::Pareto(scenario, &cases))?;
            pareto.caption = format!("{scenario}: quality against time");
            written.push(pareto);
        }
    }
    Ok(written)
}

type Area<'a, DB> = DrawingArea<DB, Shift>;
type DrawResult = Result<(), String>;

/// One plot and its data, drawable on any plotters backend.
enum Plot<'a> {
    Errors(&'a str, &'a [&'a CaseResult]),
    Timings(&'a str, &'a [&'a CaseResult]),
    Convergence(&'a str, &'a [&'a CaseResult]),
    Scaling(&'a [&'a CaseResult]),
    Table1(&'a [&'a CaseResult]),
    Pareto(&'a str, &'a [&'a CaseResult]),
    /// The cases of a dataset run: per measure, the fraction of cases whose error is at most x.
    DatasetEcdf(&'a [&'a CaseResult]),
    /// The cases of a dataset run: time per edit and precompute against #V, fitted slopes.
    DatasetCost(&'a [&'a CaseResult]),
    /// The cases of the size series: time per edit, precompute and peak memory against #V.
    SizeSeries(&'a [&'a CaseResult]),
}

impl Plot<'_> {
    /// Pixel size of the plot.
    fn size(&self) -> (u32, u32) {
        match self {
            Plot::Errors(..) => ERRORS_SIZE,
            Plot::Pareto(..) => PARETO_SIZE,
            Plot::DatasetEcdf(..) => ECDF_SIZE,
            Plot::DatasetCost(..) => ERRORS_SIZE,
            Plot::SizeSeries(..) => SIZE_SERIES_SIZE,
            _ => SIZE,
        }
    }

    fn draw<DB: DrawingBackend>(&self, root: Area<'_, DB>) -> DrawResult {
        match self {
            Plot::Errors(scenario, cases) => draw_errors(root, scenario, cases),
            Plot::Timings(scenario, cases) => draw_timings(root, scenario, cases),
            Plot::Convergence(scenario, cases) => draw_convergence(root, scenario, cases),
            Plot::Scaling(cases) => draw_scaling(root, cases),
            Plot::Table1(cases) => draw_table1(root, cases),
            Plot::Pareto(scenario, cases) => draw_pareto(root, scenario, cases),
            Plot::DatasetEcdf(cases) => draw_dataset_ecdf(root, cases),
            Plot::DatasetCost(cases) => draw_dataset_cost(root, cases),
            Plot::SizeSeries(cases) => draw_size_series(root, cases),
        }
    }
}

/// Draw `plot` into `plots/<stem>.png` and `.svg` under `dir`; returns the PNG in `group`, captioned
/// by its stem.
fn save(dir: &Path, stem: &str, group: ImageGroup, plot: &Plot<'_>) -> Result<Image, HarnessError> {
    let png = PathBuf::from("plots").join(format!("{stem}.png"));
    let svg = PathBuf::from("plots").join(format!("{stem}.svg"));
    let fail = |path: &Path, message: String| HarnessError::Report(format!("{}: {message}", path.display()));

    let final_png = dir.join(&png);
    // The bitmap backend picks the encoder from the extension, so the temporary name ends in .png.
    let temporary = dir.join(format!("plots/.{stem}.partial.png"));
    {
        let root = BitMapBackend::new(&temporary, plot.size()).into_drawing_area();
        plot.draw(root.clone()).map_err(|m| fail(&final_png, m))?;
        root.present().map_err(|e| fail(&final_png, e.to_string()))?;
    }
    std::fs::rename(&temporary, &final_png)
        .map_err(|error| HarnessError::Io { path: final_png.clone(), error })?;

    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, plot.size()).into_drawing_area();
        plot.draw(root.clone()).map_err(|m| fail(&dir.join(&svg), m))?;
        root.present().map_err(|e| fail(&dir.join(&svg), e.to_string()))?;
    }
    let final_svg = dir.join(&svg);
    meshes::io::atomic_write(&final_svg, |w| w.write_all(text.as_bytes()).map_err(meshes::MeshError::from))?;
    Ok(Image { group, path: png, caption: stem.to_string() })
}

fn err<E: std::fmt::Display>(e: E) -> String {
    e.to_string()
}

type CategoryChart<'a, DB> = ChartContext<
    'a,
    DB,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// A bar chart with one category per case (`i..i + 1` on x, method names below) and `0..top` on y.
fn category_chart<'a, DB: DrawingBackend>(
    root: &'a Area<'_, DB>,
    title: &str,
    y_desc: &str,
    cases: &[&CaseResult],
    top: f64,
) -> Result<CategoryChart<'a, DB>, String> {
    let n = cases.len().max(1);
    let mut chart = ChartBuilder::on(root)
        .caption(title, ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(70)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..n as f64, 0.0..top)
        .map_err(err)?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_labels(0)
        .y_desc(y_desc)
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(err)?;
    label_categories(root, &chart, cases)?;
    Ok(chart)
}

/// Colour swatches with labels in the upper left of a category chart (`n` categories, y up to
/// `top`).
fn swatch_legend<DB: DrawingBackend>(
    chart: &mut CategoryChart<'_, DB>,
    n: usize,
    top: f64,
    entries: &[(&str, ShapeStyle)],
) -> DrawResult {
    let n = n as f64;
    for (k, (label, style)) in entries.iter().enumerate() {
        let y = top * (0.95 - 0.06 * k as f64);
        chart
            .draw_series(std::iter::once(Rectangle::new([(0.05 * n, y), (0.08 * n, y - 0.03 * top)], *style)))
            .map_err(err)?;
        chart
            .draw_series(std::iter::once(Text::new(
                label.to_string(),
                (0.09 * n, y + 0.005 * top),
                ("sans-serif", 14),
            )))
            .map_err(err)?;
    }
    Ok(())
}

/// The method names under the bars of a category chart (category `i` spans `i..i + 1` on x),
/// drawn on `root` below the x axis.
fn label_categories<DB: DrawingBackend>(
    root: &Area<'_, DB>,
    chart: &CategoryChart<'_, DB>,
    cases: &[&CaseResult],
) -> DrawResult {
    let style = TextStyle::from(("sans-serif", 13).into_font()).pos(plotters::style::text_anchor::Pos::new(
        plotters::style::text_anchor::HPos::Center,
        plotters::style::text_anchor::VPos::Top,
    ));
    for (i, c) in cases.iter().enumerate() {
        let (x, y) = chart.backend_coord(&(i as f64 + 0.5, 0.0));
        root.draw(&Text::new(c.method.clone(), (x, y + 8), style.clone())).map_err(err)?;
    }
    Ok(())
}

/// One panel per plotted metric of [`METRICS`], side by side, sharing the method names on the left:
/// a horizontal bar per method (suspect cases hatched lighter, with the word `suspect`).
fn draw_errors<DB: DrawingBackend>(root: Area<'_, DB>, scenario: &str, cases: &[&CaseResult]) -> DrawResult {
    root.fill(&WHITE).map_err(err)?;
    let root = root
        .titled(
            &format!("{scenario}: shape errors against the rest mesh (lower is better)"),
            ("sans-serif", 22),
        )
        .map_err(err)?;
    let plotted: Vec<&MetricSpec> = METRICS.iter().filter(|s| s.plotted).collect();
    let names_w = 150;
    let (names, panels) = root.split_horizontally(names_w);
    let panels = panels.split_evenly((1, plotted.len().max(1)));
    let n = cases.len().max(1) as f64;
    let mut row_y: Vec<i32> = Vec::new();
    for (panel, spec) in panels.iter().zip(&plotted) {
        let values: Vec<f64> = cases.iter().map(|c| c.metric(spec.metric)).collect();
        let top = values.iter().filter(|v| v.is_finite()).fold(0.0f64, |m, v| m.max(v.abs())).max(1e-6) * 1.3;
        let unit = if spec.unit.is_empty() { String::new() } else { format!(" ({})", spec.unit) };
        let mut chart = ChartBuilder::on(panel)
            .caption(format!("{}{unit}", spec.label), ("sans-serif", 18))
            .margin(10)
            .x_label_area_size(30)
            .build_cartesian_2d(0.0..top, 0.0..n)
            .map_err(err)?;
        chart
            .configure_mesh()
            .disable_y_mesh()
            .y_labels(0)
            .x_labels(4)
            .label_style(("sans-serif", 13))
            .draw()
            .map_err(err)?;
        row_y.clear();
        for (i, (c, value)) in cases.iter().zip(&values).enumerate() {
            let y = n - 1.0 - i as f64;
            row_y.push(chart.backend_coord(&(0.0, y + 0.5)).1);
            let color = method_color(&c.method, cases);
            let text = if value.is_finite() {
                let faded = c.status.is_suspect() || c.status.is_unfinished();
                let style = if faded { color.mix(0.4).filled() } else { color.filled() };
                chart
                    .draw_series(std::iter::once(Rectangle::new(
                        [(0.0, y + 0.15), (value.abs(), y + 0.85)],
                        style,
                    )))
                    .map_err(err)?;
                let mut text = spec.format.apply(Some(*value));
                if c.status.is_suspect() || c.status.is_unfinished() {
                    text.push(' ');
                    text.push_str(c.status.kind());
                }
                text
            } else if c.status.is_failed() {
                "failed".to_string()
            } else {
                "–".to_string()
            };
            let at = (value.abs().min(top).max(0.0) + 0.01 * top, y + 0.35);
            let at = if value.is_finite() { at } else { (0.01 * top, y + 0.35) };
            chart.draw_series(std::iter::once(Text::new(text, at, ("sans-serif", 12)))).map_err(err)?;
        }
    }
    let (_, names_top) = names.get_base_pixel();
    let style = TextStyle::from(("sans-serif", 14).into_font()).pos(plotters::style::text_anchor::Pos::new(
        plotters::style::text_anchor::HPos::Right,
        plotters::style::text_anchor::VPos::Center,
    ));
    for (c, y) in cases.iter().zip(&row_y) {
        // `row_y` is in backend pixels; the names area draws relative to its own corner.
        names
            .draw(&Text::new(c.method.clone(), (names_w as i32 - 8, y - names_top), style.clone()))
            .map_err(err)?;
    }
    Ok(())
}

/// Stacked bars: precompute, handle bind (all steps) and solve (all steps) per method, seconds.
fn draw_timings<DB: DrawingBackend>(root: Area<'_, DB>, scenario: &str, cases: &[&CaseResult]) -> DrawResult {
    root.fill(&WHITE).map_err(err)?;
    let parts = |c: &CaseResult| {
        let bind: f64 = c.steps.iter().map(|s| s.bind_s).sum();
        [c.precompute_s, bind, c.solve_s].map(|v| if v.is_finite() { v } else { 0.0 })
    };
    let highest = |c: &&CaseResult| {
        let whisker = c.spread.map_or(0.0, |s| s.total_s.max).max(0.0);
        parts(c).iter().sum::<f64>().max(if whisker.is_finite() { whisker } else { 0.0 })
    };
    let top = cases.iter().map(highest).fold(0.0, f64::max).max(1e-3) * 1.12;
    let n = cases.len().max(1);
    let title = format!("{scenario}: time per phase (seconds)");
    let mut chart = category_chart(&root, &title, "seconds", cases, top)?;
    let phase_colors = [RGBColor(120, 120, 200), RGBColor(230, 160, 60), RGBColor(90, 170, 90)];
    for (i, c) in cases.iter().enumerate() {
        let mut bottom = 0.0;
        for (value, color) in parts(c).iter().zip(phase_colors) {
            let x = i as f64;
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(x + 0.2, bottom), (x + 0.8, bottom + value)],
                    color.filled(),
                )))
                .map_err(err)?;
            bottom += value;
        }
        // The spread of the total over the repetitions, as a whisker.
        if let Some(spread) = c.spread.filter(|s| s.repetitions > 1 && s.total_s.max.is_finite()) {
            let (x, lo, hi) = (i as f64 + 0.5, spread.total_s.min, spread.total_s.max);
            let whisker = [(x, lo), (x, hi)];
            let caps = [[(x - 0.1, lo), (x + 0.1, lo)], [(x - 0.1, hi), (x + 0.1, hi)]];
            chart
                .draw_series(std::iter::once(PathElement::new(whisker, BLACK.stroke_width(2))))
                .map_err(err)?;
            chart
                .draw_series(caps.into_iter().map(|c| PathElement::new(c, BLACK.stroke_width(2))))
                .map_err(err)?;
        }
        chart
            .draw_series(std::iter::once(Text::new(
                format!("{bottom:.3}"),
                (i as f64 + 0.25, bottom + 0.015 * top),
                ("sans-serif", 12),
            )))
            .map_err(err)?;
    }
    let labels = ["precompute", "handle bind", "solve (iterations)"];
    let entries: Vec<(&str, ShapeStyle)> =
        labels.iter().zip(phase_colors).map(|(l, c)| (*l, c.filled())).collect();
    swatch_legend(&mut chart, n, top, &entries)?;
    Ok(())
}

/// Three panels over the iterations of every method (all edit steps in sequence): step size
/// (log), `E_theta` and `E_phi` (degrees, where recorded).
fn draw_convergence<DB: DrawingBackend>(
    root: Area<'_, DB>,
    scenario: &str,
    cases: &[&CaseResult],
) -> DrawResult {
    root.fill(&WHITE).map_err(err)?;
    let root =
        root.titled(&format!("{scenario}: convergence per iteration"), ("sans-serif", 22)).map_err(err)?;
    let panels = root.split_evenly((1, 3));
    // Log x axis over iteration + 1: the unreduced methods take 1000+ iterations, the reduced ones
    // and scale_aware tens, and both ends must be readable.
    let max_iter = cases.iter().map(|c| c.trace.len()).max().unwrap_or(1).max(2) as f64 + 1.0;
    type Series = fn(&crate::record::IterationRecord) -> Option<f64>;
    let specs: [(&str, Series, bool); 3] = [
        ("step / diagonal", |t| Some(t.step), true),
        ("E_θ (degrees)", |t| t.e_theta_deg, false),
        ("E_φ (degrees)", |t| t.e_phi_deg, false),
    ];
    for (panel, (label, value, log)) in panels.iter().zip(specs) {
        let points = |c: &CaseResult| -> Vec<(f64, f64)> {
            c.trace
                .iter()
                .enumerate()
                .filter_map(|(i, t)| value(t).map(|v| (i as f64 + 1.0, v)))
                .filter(|(_, v)| v.is_finite() && (!log || *v > 0.0))
                .collect()
        };
        let all: Vec<f64> = cases.iter().flat_map(|c| points(c)).map(|(_, v)| v).collect();
        let (lo, hi) = all.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
        let (lo, hi) = if lo.is_finite() { (lo, hi) } else { (1e-6, 1.0) };
        let mut builder = ChartBuilder::on(panel);
        builder.margin(8).x_label_area_size(36).y_label_area_size(56);
        if log {
            let y = (lo.max(1e-16) * 0.8..hi * 1.25).log_scale();
            let mut chart = builder.build_cartesian_2d((1.0..max_iter).log_scale(), y).map_err(err)?;
            convergence_lines(&mut chart, cases, &points, label)?;
            draw_legend(&mut chart, SeriesLabelPosition::LowerLeft, 12)?;
        } else {
            let span = (hi - lo).max(1e-9);
            let y = (lo - 0.05 * span).max(0.0)..hi + 0.05 * span;
            let mut chart = builder.build_cartesian_2d((1.0..max_iter).log_scale(), y).map_err(err)?;
            convergence_lines(&mut chart, cases, &points, label)?;
        }
    }
    Ok(())
}

/// The axes (labelled `label` on y) and one labelled line per case of a convergence panel.
fn convergence_lines<'a, DB: DrawingBackend + 'a, X: Ranged<ValueType = f64>, Y: Ranged<ValueType = f64>>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<X, Y>>,
    cases: &[&CaseResult],
    points: &dyn Fn(&CaseResult) -> Vec<(f64, f64)>,
    label: &str,
) -> DrawResult
where
    X: ValueFormatter<f64>,
    Y: ValueFormatter<f64>,
{
    chart
        .configure_mesh()
        .x_desc("iteration + 1")
        .y_desc(label)
        .label_style(("sans-serif", 12))
        .draw()
        .map_err(err)?;
    for c in cases {
        let style = method_color(&c.method, cases).stroke_width(2);
        chart
            .draw_series(LineSeries::new(points(c), style))
            .map_err(err)?
            .label(c.method.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], style));
    }
    Ok(())
}

/// Log-log median iteration time against vertex count, one line per method.
fn draw_scaling<DB: DrawingBackend>(root: Area<'_, DB>, sweeps: &[&CaseResult]) -> DrawResult {
    root.fill(&WHITE).map_err(err)?;
    let mut methods: Vec<&str> = Vec::new();
    for r in sweeps {
        if !methods.contains(&r.method.as_str()) {
            methods.push(&r.method);
        }
    }
    let line = |m: &str| -> Vec<(f64, f64)> {
        let mut points: Vec<(f64, f64)> = sweeps
            .iter()
            .filter(|r| r.method == m && r.median_iteration_ms > 0.0 && r.median_iteration_ms.is_finite())
            .map(|r| (r.vertices as f64, r.median_iteration_ms))
            .collect();
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
        points
    };
    let all: Vec<(f64, f64)> = methods.iter().flat_map(|m| line(m)).collect();
    let (x0, x1) = all.iter().fold((f64::INFINITY, 0.0f64), |(a, b), p| (a.min(p.0), b.max(p.0)));
    let (y0, y1) = all.iter().fold((f64::INFINITY, 0.0f64), |(a, b), p| (a.min(p.1), b.max(p.1)));
    if !x0.is_finite() {
        return Ok(());
    }
    let mut chart = ChartBuilder::on(&root)
        .caption("Per-iteration time against mesh size (resolution sweep)", ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d((x0 * 0.7..x1 * 1.4).log_scale(), (y0 * 0.5..y1 * 2.0).log_scale())
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("vertices")
        .y_desc("median iteration (ms)")
        // Log axes put a label at every mantissa step; a few readable ones are enough.
        .x_labels(6)
        .x_label_formatter(&|v| vertex_count_label(*v))
        .y_label_formatter(&|v| format!("{v}"))
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(err)?;
    for m in methods {
        let color = method_color(m, sweeps);
        labelled_line(&mut chart, line(m), color, color.stroke_width(2), m.to_string())?;
    }
    draw_legend(&mut chart, SeriesLabelPosition::UpperLeft, 14)
}

/// The dataset's error distributions: one panel per measure of
/// [`crate::report::dataset::SPREAD_MEASURES`], for every method the fraction of its cases (all
/// that were planned and loaded) whose measure is at most x, on a log x axis. Unfinished and failed
/// cases never count as reaching x, so a method's curve tops out at its finished fraction.
fn draw_dataset_ecdf<DB: DrawingBackend>(root: Area<'_, DB>, cases: &[&CaseResult]) -> DrawResult {
    use crate::report::dataset::{methods_of, SPREAD_MEASURES};
    root.fill(&WHITE).map_err(err)?;
    let root = root
        .titled(
            "Across the dataset: fraction of cases whose error is at most x (ok or suspect shapes)",
            ("sans-serif", 22),
        )
        .map_err(err)?;
    let methods = methods_of(cases);
    for (panel, measure) in root.split_evenly((3, 2)).into_iter().zip(SPREAD_MEASURES) {
        let curve = |m: &str| -> Vec<(f64, f64)> {
            let of: Vec<&&CaseResult> = cases.iter().filter(|c| c.method == m).collect();
            let mut values: Vec<f64> = of
                .iter()
                .filter(|c| c.status.is_ok() || c.status.is_suspect())
                .map(|c| c.metric(measure))
                .filter(|v| v.is_finite() && *v > 0.0)
                .collect();
            values.sort_by(f64::total_cmp);
            let n = of.len().max(1) as f64;
            let mut points = Vec::with_capacity(2 * values.len());
            for (i, v) in values.iter().enumerate() {
                points.push((*v, i as f64 / n));
                points.push((*v, (i + 1) as f64 / n));
            }
            points
        };
        let all: Vec<f64> = methods.iter().flat_map(|m| curve(m)).map(|p| p.0).collect();
        let (x0, x1) = all.iter().fold((f64::INFINITY, 0.0f64), |(a, b), &x| (a.min(x), b.max(x)));
        if !x0.is_finite() || x1 <= 0.0 {
            continue;
        }
        let spec = measure.spec();
        let unit = if spec.unit.is_empty() { String::new() } else { format!(" ({})", spec.unit) };
        let mut chart = ChartBuilder::on(&panel)
            .caption(format!("{}{unit}", spec.label), ("sans-serif", 18))
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(50)
            .build_cartesian_2d((x0 * 0.8..x1 * 1.25).log_scale(), 0.0..1.0)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_labels(6)
            .x_label_formatter(&|v| format!("{}", round_to_two_digits(*v)))
            .y_desc("fraction of cases")
            .label_style(("sans-serif", 13))
            .draw()
            .map_err(err)?;
        for m in &methods {
            let points = curve(m);
            if points.is_empty() {
                continue;
            }
            let color = method_color(m, cases);
            let style = color.stroke_width(2);
            chart
                .draw_series(LineSeries::new(points, style))
                .map_err(err)?
                .label(m.to_string())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], style));
        }
        draw_legend(&mut chart, SeriesLabelPosition::LowerRight, 13)?;
    }
    Ok(())
}

/// The dataset's cost against mesh size: time per edit (bind + solve) and precompute against #V on
/// log-log axes, a dot per case that ran and each method's least-squares line, its slope in the
/// legend ([`crate::report::dataset::cost_slope`]).
fn draw_dataset_cost<DB: DrawingBackend>(root: Area<'_, DB>, cases: &[&CaseResult]) -> DrawResult {
    use crate::report::dataset::{cost_slope, methods_of};
    root.fill(&WHITE).map_err(err)?;
    let root = root
        .titled("Across the dataset: cost against mesh size (log-log, fitted slopes)", ("sans-serif", 22))
        .map_err(err)?;
    let methods = methods_of(cases);
    let axes: [(&str, fn(&CaseResult) -> f64); 2] = [
        ("time per edit, bind + solve (s)", |c| c.bind_s + c.solve_s),
        ("precompute (s)", |c| c.precompute_s),
    ];
    for (panel, (label, seconds)) in root.split_evenly((1, 2)).into_iter().zip(axes) {
        let points = |m: &str| -> Vec<(f64, f64)> {
            cases
                .iter()
                .filter(|c| c.method == m && !c.status.is_failed())
                .map(|c| (c.vertices as f64, seconds(c)))
                .filter(|(v, t)| *v > 0.0 && t.is_finite() && *t > 0.0)
                .collect()
        };
        let all: Vec<(f64, f64)> = methods.iter().flat_map(|m| points(m)).collect();
        let Some(mut chart) = against_vertices(&panel, label, "seconds", &all)? else { continue };
        for m in &methods {
            let p = points(m);
            if p.is_empty() {
                continue;
            }
            let color = method_color(m, cases);
            chart.draw_series(p.iter().map(|q| Circle::new(*q, 2, color.mix(0.5).filled()))).map_err(err)?;
            let (slope, _) = cost_slope(p.iter().map(|(v, t)| (*v as usize, *t)));
            if !slope.is_finite() {
                continue;
            }
            let n = p.len() as f64;
            let (mx, my) = p.iter().fold((0.0, 0.0), |(a, b), (v, t)| (a + v.ln() / n, b + t.ln() / n));
            let (lo, hi) = p.iter().fold((f64::INFINITY, 0.0f64), |(a, b), q| (a.min(q.0), b.max(q.0)));
            let fit = |v: f64| (my + slope * (v.ln() - mx)).exp();
            let style = color.stroke_width(2);
            chart
                .draw_series(LineSeries::new(vec![(lo, fit(lo)), (hi, fit(hi))], style))
                .map_err(err)?
                .label(format!("{m} (slope {slope:.2})"))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], style));
        }
        draw_legend(&mut chart, SeriesLabelPosition::UpperLeft, 13)?;
    }
    Ok(())
}

/// The size series' cost against #V: time per edit, precompute and peak memory on log-log axes, a
/// marker per case that ran and a line through each (series, method)'s sizes, its fitted slope in
/// the legend. Colour says the method, the marker the series (circle, triangle, square, ...).
fn draw_size_series<DB: DrawingBackend>(root: Area<'_, DB>, cases: &[&CaseResult]) -> DrawResult {
    use crate::report::dataset::{cost_slope, methods_of};
    root.fill(&WHITE).map_err(err)?;
    let root = root
        .titled("Cost against size: one shape at several sizes (log-log, fitted slopes)", ("sans-serif", 22))
        .map_err(err)?;
    let methods = methods_of(cases);
    let mut series: Vec<&str> = cases.iter().filter_map(|c| c.series.as_deref()).collect();
    series.sort();
    series.dedup();
    let panels: [(&str, &str, fn(&CaseResult) -> f64); 3] = [
        ("time per edit, bind + solve", "seconds", |c| c.bind_s + c.solve_s),
        ("precompute", "seconds", |c| c.precompute_s),
        ("peak memory", "MiB", |c| c.peak_memory_mib),
    ];
    for (panel, (label, unit, value)) in root.split_evenly((1, 3)).into_iter().zip(panels) {
        let points = |s: &str, m: &str| -> Vec<(f64, f64)> {
            let mut p: Vec<(f64, f64)> = cases
                .iter()
                .filter(|c| c.series.as_deref() == Some(s) && c.method == m && !c.status.is_failed())
                .map(|c| (c.vertices as f64, value(c)))
                .filter(|(v, y)| *v > 0.0 && y.is_finite() && *y > 0.0)
                .collect();
            p.sort_by(|a, b| a.0.total_cmp(&b.0));
            p
        };
        let all: Vec<(f64, f64)> =
            series.iter().flat_map(|s| methods.iter().flat_map(move |m| points(s, m))).collect();
        let Some(mut chart) = against_vertices(&panel, label, unit, &all)? else { continue };
        for (k, s) in series.iter().enumerate() {
            for m in &methods {
                let p = points(s, m);
                if p.is_empty() {
                    continue;
                }
                let color = method_color(m, cases);
                let style = color.stroke_width(if k == 0 { 2 } else { 1 });
                let (slope, _) = cost_slope(p.iter().map(|(v, y)| (*v as usize, *y)));
                let slope = if slope.is_finite() { format!("{slope:.2}") } else { "–".into() };
                chart
                    .draw_series(LineSeries::new(p.clone(), style))
                    .map_err(err)?
                    .label(format!("{s}: {m} (slope {slope})"))
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], style));
                for q in p {
                    let marker: DynElement<DB, (f64, f64)> = match k % 3 {
                        0 => Circle::new(q, 4, color.filled()).into_dyn(),
                        1 => TriangleMarker::new(q, 5, color.filled()).into_dyn(),
                        _ => Cross::new(q, 4, color.stroke_width(2)).into_dyn(),
                    };
                    chart.draw_series(std::iter::once(marker)).map_err(err)?;
                }
            }
        }
        draw_legend(&mut chart, SeriesLabelPosition::UpperLeft, 12)?;
    }
    Ok(())
}

/// Log-log axes of `unit` against vertex count on `panel`, captioned `label`, spanning `points`
/// with a margin; `None` when there is no point to draw.
#[allow(clippy::type_complexity)]
fn against_vertices<'a, DB: DrawingBackend>(
    panel: &Area<'a, DB>,
    label: &str,
    unit: &str,
    points: &[(f64, f64)],
) -> Result<Option<ChartContext<'a, DB, Cartesian2d<LogCoord<f64>, LogCoord<f64>>>>, String> {
    let (x0, x1) = points.iter().fold((f64::INFINITY, 0.0f64), |(a, b), p| (a.min(p.0), b.max(p.0)));
    let (y0, y1) = points.iter().fold((f64::INFINITY, 0.0f64), |(a, b), p| (a.min(p.1), b.max(p.1)));
    if !x0.is_finite() {
        return Ok(None);
    }
    let mut chart = ChartBuilder::on(panel)
        .caption(label, ("sans-serif", 18))
        .margin(10)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d((x0 * 0.8..x1 * 1.25).log_scale(), (y0 * 0.5..y1 * 2.0).log_scale())
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("vertices")
        .y_desc(unit)
        .x_labels(6)
        .x_label_formatter(&|v| vertex_count_label(*v))
        .y_label_formatter(&|v| format!("{}", round_to_two_digits(*v)))
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(err)?;
    Ok(Some(chart))
}

/// A vertex count for an axis: `6K`, `50K`, `1.2M`.
fn vertex_count_label(v: f64) -> String {
    if v >= 1e6 {
        format!("{}M", round_to_two_digits(v / 1e6))
    } else if v >= 1e3 {
        format!("{}K", round_to_two_digits(v / 1e3))
    } else {
        format!("{}", v.round())
    }
}

/// `v` rounded to two significant digits, without trailing zeros.
fn round_to_two_digits(v: f64) -> f64 {
    if v <= 0.0 || !v.is_finite() {
        return v;
    }
    let scale = 10f64.powi(1 - v.log10().floor() as i32);
    (v * scale).round() / scale
}

/// A polyline with a dot on every point, labelled for the legend.
fn labelled_line<'a, DB: DrawingBackend + 'a, X: Ranged<ValueType = f64>, Y: Ranged<ValueType = f64>>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<X, Y>>,
    points: Vec<(f64, f64)>,
    color: RGBColor,
    style: ShapeStyle,
    label: String,
) -> DrawResult {
    chart
        .draw_series(LineSeries::new(points.clone(), style))
        .map_err(err)?
        .label(label)
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], style));
    chart.draw_series(points.into_iter().map(|p| Circle::new(p, 4, color.filled()))).map_err(err)?;
    Ok(())
}

/// The series legend at `position`, in `font_size` pixels.
fn draw_legend<'a, DB: DrawingBackend + 'a, X: Ranged<ValueType = f64>, Y: Ranged<ValueType = f64>>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<X, Y>>,
    position: SeriesLabelPosition,
    font_size: u32,
) -> DrawResult {
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", font_size))
        .draw()
        .map_err(err)
}

/// Handle-set update time against the number of handles: `hirm`'s `t_h` and the `isolines`
/// rebuild (its whole bind), one line each per `*-handles` scenario (log time axis).
fn draw_table1<DB: DrawingBackend>(root: Area<'_, DB>, cases: &[&CaseResult]) -> DrawResult {
    root.fill(&WHITE).map_err(err)?;
    let series = |c: &CaseResult| -> Vec<(f64, f64)> {
        c.steps
            .iter()
            .filter_map(|s| {
                let side = methods::registry::table1_side(&c.method);
                let seconds = if side == Some(methods::registry::Table1Side::HandleIndependent) {
                    s.phase_timings
                        .iter()
                        .find(|(k, _)| k == methods::keys::phase::T_H_HANDLE_UPDATE)
                        .map(|(_, v)| *v)?
                } else {
                    s.bind_s
                };
                (seconds > 0.0 && seconds.is_finite()).then_some((s.handles as f64, 1e3 * seconds))
            })
            .collect()
    };
    let all: Vec<(f64, f64)> = cases.iter().flat_map(|c| series(c)).collect();
    if all.is_empty() {
        return Ok(());
    }
    let x1 = all.iter().map(|p| p.0).fold(0.0, f64::max);
    let (y0, y1) = all.iter().fold((f64::INFINITY, 0.0f64), |(a, b), p| (a.min(p.1), b.max(p.1)));
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "Handle-set update: hirm t_h against the isolines rebuild (HIRM Table 1)",
            ("sans-serif", 20),
        )
        .margin(12)
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..x1 + 1.0, (y0 * 0.5..y1 * 2.0).log_scale())
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("handles (fixed region included)")
        .y_desc("update time (ms)")
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(err)?;
    for c in cases {
        let color = method_color(&c.method, cases);
        let dashed = c.scenario.starts_with("cactus");
        let label = format!("{} ({})", c.method, c.scenario);
        let points = series(c);
        let style = color.stroke_width(if dashed { 1 } else { 3 });
        labelled_line(&mut chart, points, color, style, label)?;
    }
    draw_legend(&mut chart, SeriesLabelPosition::UpperRight, 14)
}

/// Quality against time for one scenario: a panel per measure of [`crate::pareto::MEASURES`] (rows)
/// and time axis (columns).
fn draw_pareto<DB: DrawingBackend>(root: Area<'_, DB>, scenario: &str, cases: &[&CaseResult]) -> DrawResult {
    use crate::pareto::{TimeAxis, MEASURES};
    root.fill(&WHITE).map_err(err)?;
    let root = root
        .titled(
            &format!("{scenario}: quality against time; black: the front of the ok settings (none both faster and better); x: suspect"),
            ("sans-serif", 24),
        )
        .map_err(err)?;
    let panels = root.split_evenly((MEASURES.len(), TimeAxis::ALL.len()));
    for (i, panel) in panels.iter().enumerate() {
        let measure = MEASURES[i / TimeAxis::ALL.len()];
        let axis = TimeAxis::ALL[i % TimeAxis::ALL.len()];
        draw_pareto_panel(panel, cases, measure, axis, i == 0)?;
    }
    Ok(())
}

/// A chart with log axes for time and error.
type LogLogChart<'a, DB> = ChartContext<'a, DB, Cartesian2d<LogCoord<f64>, LogCoord<f64>>>;

/// Log axes need positive values: a time or error of 0 sits at the axis' floor.
const LOG_FLOOR: f64 = 1e-6;

/// Where a point sits on the log axes: its time and error, floored at [`LOG_FLOOR`].
fn on_log_axes(p: &crate::pareto::Point) -> (f64, f64) {
    (p.time.max(LOG_FLOOR), p.error.max(LOG_FLOOR))
}

/// One panel of [`draw_pareto`]: `measure` against the time `axis`, each sweep a line, the front a
/// staircase with its settings named, the points in their base method's colour (suspect ones
/// crossed); the first panel (`legend`) carries the legend.
fn draw_pareto_panel<DB: DrawingBackend>(
    root: &Area<'_, DB>,
    cases: &[&CaseResult],
    measure: crate::metrics::Metric,
    axis: crate::pareto::TimeAxis,
    legend: bool,
) -> DrawResult {
    let placed = crate::pareto::points(cases, axis, measure);
    if placed.is_empty() {
        return Ok(());
    }
    let at: Vec<(f64, f64)> = placed.iter().map(|(_, p)| on_log_axes(p)).collect();
    let x_end = at.iter().fold(0.0f64, |b, p| b.max(p.0)) * 1.7;
    let mut chart = pareto_chart(root, &at, measure, axis)?;
    draw_sweep_lines(&mut chart, &placed, &at, cases)?;
    let front = crate::pareto::ok_front(&placed);
    draw_front_staircase(&mut chart, &front, &at, x_end)?;
    draw_pareto_points(&mut chart, &placed, &at, cases, legend)?;
    name_front_points(&mut chart, &placed, &front, &at)?;
    if legend {
        draw_legend(&mut chart, SeriesLabelPosition::UpperRight, 13)?;
    }
    Ok(())
}

/// The panel's chart: log axes around the points `at`, with their caption, labels and grid.
fn pareto_chart<'a, DB: DrawingBackend>(
    root: &Area<'a, DB>,
    at: &[(f64, f64)],
    measure: crate::metrics::Metric,
    axis: crate::pareto::TimeAxis,
) -> Result<LogLogChart<'a, DB>, String> {
    let (x0, x1) = at.iter().fold((f64::INFINITY, 0.0f64), |(a, b), p| (a.min(p.0), b.max(p.0)));
    let (y0, y1) = at.iter().fold((f64::INFINITY, 0.0f64), |(a, b), p| (a.min(p.1), b.max(p.1)));
    let spec = measure.spec();
    let unit = if spec.unit.is_empty() { String::new() } else { format!(" ({})", spec.unit) };
    let mut chart = ChartBuilder::on(root)
        .caption(format!("{}{unit} against {}", spec.label, axis.label()), ("sans-serif", 17))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d((x0 * 0.6..x1 * 1.7).log_scale(), (y0 * 0.8..y1 * 1.25).log_scale())
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc(axis.label())
        .y_desc(format!("{}{unit}", spec.label))
        .x_labels(6)
        .y_labels(6)
        .x_label_formatter(&|v| format!("{v:.0e}"))
        .y_label_formatter(&|v| format!("{}", round_to_two_digits(*v)))
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(err)?;
    Ok(chart)
}

/// Each sweep's points (placed at `at`) joined in parameter order, in its base method's colour.
fn draw_sweep_lines<DB: DrawingBackend>(
    chart: &mut LogLogChart<'_, DB>,
    placed: &[(&CaseResult, crate::pareto::Point)],
    at: &[(f64, f64)],
    cases: &[&CaseResult],
) -> DrawResult {
    let mut sweeps: Vec<&str> = Vec::new();
    for (c, _) in placed {
        for p in &c.sweeps {
            if !sweeps.contains(&p.sweep.as_str()) {
                sweeps.push(&p.sweep);
            }
        }
    }
    for sweep in sweeps {
        let mut line: Vec<(usize, &CaseResult, (f64, f64))> = placed
            .iter()
            .zip(at)
            .filter_map(|((c, _), &xy)| {
                c.sweeps.iter().find(|s| s.sweep == sweep).map(|s| (s.position, *c, xy))
            })
            .collect();
        line.sort_by_key(|(position, _, _)| *position);
        let Some((_, first, _)) = line.first() else { continue };
        let color = method_color(crate::sweep::base_method(&first.method), cases);
        chart
            .draw_series(LineSeries::new(line.iter().map(|(_, _, p)| *p), color.mix(0.6).stroke_width(1)))
            .map_err(err)?;
    }
    Ok(())
}

/// The front of the `ok` points (`front`, fastest first): a black staircase through them, on to
/// `x_end`.
fn draw_front_staircase<DB: DrawingBackend>(
    chart: &mut LogLogChart<'_, DB>,
    front: &[usize],
    at: &[(f64, f64)],
    x_end: f64,
) -> DrawResult {
    let mut stairs: Vec<(f64, f64)> = Vec::new();
    for &i in front {
        let (x, y) = at[i];
        if let Some(&(_, last_y)) = stairs.last() {
            stairs.push((x, last_y));
        }
        stairs.push((x, y));
    }
    if let Some(&(_, y)) = stairs.last() {
        stairs.push((x_end, y));
    }
    chart.draw_series(LineSeries::new(stairs, BLACK.stroke_width(2))).map_err(err)?;
    Ok(())
}

/// The points in their base method's colour, suspect ones crossed; with `legend`, one legend entry
/// per base method.
fn draw_pareto_points<DB: DrawingBackend>(
    chart: &mut LogLogChart<'_, DB>,
    placed: &[(&CaseResult, crate::pareto::Point)],
    at: &[(f64, f64)],
    cases: &[&CaseResult],
    legend: bool,
) -> DrawResult {
    let mut labelled: Vec<&str> = Vec::new();
    for ((c, _), &at) in placed.iter().zip(at) {
        let base = crate::sweep::base_method(&c.method);
        let color = method_color(base, cases);
        let series = chart.draw_series(std::iter::once(Circle::new(at, 5, color.filled()))).map_err(err)?;
        if legend && !labelled.contains(&base) {
            labelled.push(base);
            series.label(base.to_string()).legend(move |(x, y)| Circle::new((x + 8, y), 5, color.filled()));
        }
        if c.status.is_suspect() {
            chart
                .draw_series(std::iter::once(Cross::new(at, 7, RGBColor(200, 0, 0).stroke_width(2))))
                .map_err(err)?;
        }
    }
    Ok(())
}

/// The front's points by name, so a reader can tell which setting each is.
fn name_front_points<DB: DrawingBackend>(
    chart: &mut LogLogChart<'_, DB>,
    placed: &[(&CaseResult, crate::pareto::Point)],
    front: &[usize],
    at: &[(f64, f64)],
) -> DrawResult {
    for &i in front {
        let name = format!(" {}", placed[i].0.method);
        let font = ("sans-serif", 12).into_font().color(&BLACK);
        chart.draw_series(std::iter::once(Text::new(name, at[i], font))).map_err(err)?;
    }
    Ok(())
}
