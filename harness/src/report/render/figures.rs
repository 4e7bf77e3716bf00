//! The report figures: a shaded render, an angle-error heat map and an area-distortion map of every
//! result, and the three grids (rows = scenarios, columns = `rest` + methods) the survey and the
//! scale-aware paper (Fig. 10) present results in.
//!
//! One camera per row frames the rest shape and the handle targets (each step's targets applied to
//! the rest shape), never the results: a result that runs away cannot shrink the row to a dot. A
//! result that leaves that frame is drawn clipped and its cell marked `clipped`; a suspect case is
//! marked `suspect` (its reasons are in the reports).
//!
//! Rows are the scenarios of `scenarios` (in that order) with at least one result; a result whose
//! scenario is not among them has no rest mesh to render and is left out. Columns are the same for
//! every row: every method with a result, in registry order (unknown names after, in order of first
//! appearance), so a method stays in one column; a scenario that did not run a method gets a
//! `not run` cell there, a failed case (status not `ok`, or no `#V x 3` positions) a `failed` cell.

use std::path::{Path, PathBuf};

use rayon::prelude::*;

use crate::error::HarnessError;
use crate::metrics::Metric;
use crate::record::CaseResult;
use crate::report::document::{Image, ImageGroup};
use crate::scenario::{LoadedScenario, Role};

use super::camera::{Camera, VIEW_FROM};
use super::canvas::RgbImage;
use super::heat::{
    area_color, heat_color, vertex_angle_errors, vertex_area_distortion, AREA_MAX_LOG, HEAT_MAX_DEG,
};
use super::shade::{render, Paint, VertexRole};
use super::text::{draw_labels, Align, Label};

/// Side of a rendered cell, in pixels (each figure is one square cell).
pub const CELL_SIZE: u32 = 320;

/// Grid geometry, in pixels.
const PAD: u32 = 20;
const HEADER_H: u32 = 50;
const CAPTION_H: u32 = 40;
const ROW_GAP: u32 = 14;
/// Height of the legend above the notes, and of a line of notes.
const LEGEND_H: [u32; 2] = [44, 84];
const NOTE_LINE_H: u32 = 24;

/// Font sizes, in pixels: column and row names, row details and notes, cell captions, legends.
const NAME_PX: f64 = 26.0;
const DETAIL_PX: f64 = 17.0;
const CAPTION_PX: f64 = 20.0;
const LEGEND_PX: f64 = 19.0;
const TICK_PX: f64 = 16.0;

const INK: [u8; 3] = [25, 25, 25];
const MUTED: [u8; 3] = [110, 110, 110];
const FAINT: [u8; 3] = [175, 175, 175];
const RULE: [u8; 3] = [222, 222, 222];
const EMPTY_CELL: [u8; 3] = [247, 247, 247];
const FAILED_CELL: [u8; 3] = [250, 238, 238];
const FAILED_INK: [u8; 3] = [170, 50, 50];
const SUSPECT_INK: [u8; 3] = [200, 110, 0];
const UNFINISHED_INK: [u8; 3] = [40, 70, 200];

/// Folder of the figures under the report directory.
const FIGURES: &str = "figures";

/// Write `figures/<scenario>-rest.png`, `figures/<scenario>-<method>.png`,
/// `figures/<scenario>-<method>-heat.png`, `figures/<scenario>-<method>-area.png`, `figures/grid.png`,
/// `figures/grid_heat.png`, `figures/grid_area.png` under `dir`;
/// returns the images written, their paths relative to `dir`, in the page's groups (the worst-case
/// sheets `figures/worst-<family>.png` of a dataset run too).
///
/// `results` are the cases of the run (a result's `positions` are its final `#V x 3` shape on the
/// rest connectivity of its scenario); `scenarios` give the rest meshes and the handle sets (the
/// last step's: the region named `fixed` is drawn blue, every other region orange). Scenario and
/// method names are used in file names with characters other than ASCII letters, digits, `-`, `_`
/// and `.` replaced by `_`. Each file is written atomically.
///
/// Errors: no font for the labels ([`crate::report::fonts::register_sans_serif`]), or a file that cannot be
/// encoded or written (the error names it).
pub fn write_figures(
    dir: &Path,
    results: &[CaseResult],
    scenarios: &[LoadedScenario],
) -> Result<Vec<Image>, HarnessError> {
    crate::report::fonts::register_sans_serif()?;
    let columns = method_columns(results);
    let index = crate::record::CaseIndex::new(results);
    let rows: Vec<Row> = scenarios
        .iter()
        .filter(|s| results.iter().any(|r| r.scenario == s.spec.name))
        .map(|scenario| Row {
            scenario,
            label: None,
            cases: columns
                .iter()
                .map(|m| index.get(&crate::record::CaseKey::new(&scenario.spec.name, m)))
                .collect(),
        })
        .collect();
    let rendered: Vec<RenderedRow> = rows.par_iter().map(render_row).collect();

    let figures = dir.join(FIGURES);
    std::fs::create_dir_all(&figures).map_err(|error| HarnessError::Io { path: figures.clone(), error })?;
    let grids = grids(&rows, &rendered, &columns, results)
        .map_err(|(name, e)| HarnessError::Report(format!("{}: {e}", figures.join(name).display())))?;
    let mut files = single_renders(&rows, &rendered);
    for (name, group, image) in &grids {
        files.push((figure(Path::new(FIGURES).join(name), group.clone()), image));
    }
    write_pngs(dir, &files)?;
    Ok(files.into_iter().map(|(image, _)| image).collect())
}

/// `path` in `group`, captioned by its stem.
fn figure(path: PathBuf, group: ImageGroup) -> Image {
    let caption = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    Image { group, path, caption }
}

/// Every row's rest render and each of its results' shaded, heat and area renders.
fn single_renders<'a>(rows: &[Row], rendered: &'a [RenderedRow]) -> Vec<(Image, &'a RgbImage)> {
    let mut files = Vec::new();
    let mut add = |name: String, picture| {
        files.push((figure(Path::new(FIGURES).join(name), ImageGroup::Render), picture))
    };
    for (row, images) in rows.iter().zip(rendered) {
        let stem = crate::stored_report::file_name(&row.scenario.spec.name);
        add(format!("{stem}-rest.png"), &images.rest);
        for (case, cell) in row.cases.iter().zip(&images.cells) {
            if let (Some(case), Cell::Rendered { shaded, heat, area, .. }) = (case, cell) {
                let stem = format!("{stem}-{}", crate::stored_report::file_name(&case.method));
                add(format!("{stem}.png"), shaded);
                add(format!("{stem}-heat.png"), heat);
                add(format!("{stem}-area.png"), area);
            }
        }
    }
    files
}

/// The three grids (none above [`MAX_GRID_ROWS`] rows) and each family's worst-case sheet: file
/// name, group and image; an error names the file.
fn grids(
    rows: &[Row],
    rendered: &[RenderedRow],
    columns: &[String],
    results: &[CaseResult],
) -> Result<Vec<(String, ImageGroup, RgbImage)>, (String, String)> {
    let grid_kinds: &[(Kind, &str)] = if rows.len() <= MAX_GRID_ROWS {
        &[(Kind::Shaded, "grid.png"), (Kind::Heat, "grid_heat.png"), (Kind::Area, "grid_area.png")]
    } else {
        &[]
    };
    let mut grids = grid_kinds
        .iter()
        .map(|&(kind, name)| {
            let image = grid_image(rows, rendered, columns, kind).map_err(|e| (name.to_string(), e))?;
            Ok::<_, (String, String)>((name.to_string(), ImageGroup::Grid, image))
        })
        .collect::<Result<Vec<_>, _>>()?;
    for (family, (sheet_rows, sheet_rendered)) in worst_sheets(results, rows, rendered) {
        let name = format!("worst-{}.png", crate::stored_report::file_name(&family));
        let columns = ["result".to_string(), crate::record::REFERENCE_METHOD.to_string()];
        let image = grid_image(&sheet_rows, &sheet_rendered, &columns, Kind::Shaded)
            .map_err(|e| (name.clone(), e))?;
        grids.push((name, ImageGroup::Dataset, image));
    }
    Ok(grids)
}

/// Encode `files` as PNG (in parallel) and write each under `dir`, atomically.
fn write_pngs(dir: &Path, files: &[(Image, &RgbImage)]) -> Result<(), HarnessError> {
    let encoded: Vec<Result<Vec<u8>, HarnessError>> = files
        .par_iter()
        .map(|(file, image)| {
            image
                .encode_png()
                .map_err(|e| HarnessError::Report(format!("{}: PNG: {e}", dir.join(&file.path).display())))
        })
        .collect();
    for ((file, _), bytes) in files.iter().zip(encoded) {
        let bytes = bytes?;
        meshes::io::atomic_write(dir.join(&file.path), |w| {
            w.write_all(&bytes).map_err(meshes::MeshError::from)
        })?;
    }
    Ok(())
}

/// The most tests a run's grids draw: above it (a dataset run: hundreds of meshes x edits) the grids
/// would be images tens of thousands of pixels tall that nobody can look at, so only the worst-case
/// sheets and the single renders are written.
pub const MAX_GRID_ROWS: usize = 60;

/// Per edit family of a dataset run ([`crate::report::dataset::worst_ok`]), the rows of its
/// worst-case sheet: each method's worst `ok` results, each beside the reference's result on the
/// same mesh (`result`, `arap` columns), labelled `method: mesh`, with the images already rendered
/// for the run's own rows.
fn worst_sheets<'a>(
    results: &'a [CaseResult],
    rows: &[Row<'a>],
    rendered: &[RenderedRow],
) -> Vec<(String, (Vec<Row<'a>>, Vec<RenderedRow>))> {
    let cases = crate::report::dataset::dataset_cases(results);
    let mut sheets: Vec<(String, (Vec<Row>, Vec<RenderedRow>))> = Vec::new();
    for (family, method, worst) in crate::report::dataset::worst_ok(&cases) {
        if method == crate::record::REFERENCE_METHOD {
            continue;
        }
        if sheets.last().is_none_or(|(f, _)| *f != family) {
            sheets.push((family.clone(), (Vec::new(), Vec::new())));
        }
        let (sheet_rows, sheet_rendered) = &mut sheets.last_mut().expect("pushed above").1;
        for case in worst {
            let Some(i) = rows.iter().position(|r| r.scenario.spec.name == case.scenario) else { continue };
            let cell_of = |m: &str| {
                rows[i]
                    .cases
                    .iter()
                    .position(|c| c.is_some_and(|c| c.method == m))
                    .map(|k| (rows[i].cases[k], rendered[i].cells[k].clone()))
            };
            let (Some((result, result_cell)), reference) =
                (cell_of(&method), cell_of(crate::record::REFERENCE_METHOD))
            else {
                continue;
            };
            let (reference, reference_cell) = reference.unwrap_or((None, Cell::NotRun));
            let mesh = case.member.as_ref().map_or(case.scenario.as_str(), |m| m.mesh.as_str());
            sheet_rows.push(Row {
                scenario: rows[i].scenario,
                label: Some(format!("{method}: {mesh}")),
                cases: vec![result, reference],
            });
            sheet_rendered.push(RenderedRow {
                rest: rendered[i].rest.clone(),
                cells: vec![result_cell, reference_cell],
            });
        }
    }
    sheets
}

/// One grid row: a scenario and its case per column (`None`: not run), labelled with `label` (else
/// the scenario's name).
struct Row<'a> {
    scenario: &'a LoadedScenario,
    label: Option<String>,
    cases: Vec<Option<&'a CaseResult>>,
}

/// The images of a row: its rest shape and one cell per column.
struct RenderedRow {
    rest: RgbImage,
    cells: Vec<Cell>,
}

#[derive(Clone)]
enum Cell {
    NotRun,
    Failed,
    /// `clipped`: part of the result lies outside the row's frame.
    Rendered {
        shaded: RgbImage,
        heat: RgbImage,
        area: RgbImage,
        clipped: bool,
    },
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    Shaded,
    Heat,
    Area,
}

/// The `#V x 3` result of a case, if it succeeded and fits its rest mesh.
fn usable_positions<'a>(case: &'a CaseResult, scenario: &LoadedScenario) -> Option<&'a [[f64; 3]]> {
    let positions = case.positions.as_deref()?;
    (!case.status.is_failed() && positions.len() == scenario.mesh.n_vertices()).then_some(positions)
}

/// Every method with a result, in registry order, then unknown names in order of appearance.
fn method_columns(results: &[CaseResult]) -> Vec<String> {
    let mut columns: Vec<String> = methods::registry::method_names()
        .into_iter()
        .filter(|m| results.iter().any(|r| r.method == *m))
        .map(String::from)
        .collect();
    for r in results {
        if !columns.contains(&r.method) {
            columns.push(r.method.clone());
        }
    }
    columns
}

/// `#V` roles from the scenario's last handle set (which holds every region of the earlier steps):
/// fixed regions blue, every other region orange.
fn vertex_roles(scenario: &LoadedScenario) -> Vec<VertexRole> {
    let mut roles = vec![VertexRole::Free; scenario.mesh.n_vertices()];
    let Some(step) = scenario.steps.last() else { return roles };
    for (region, role) in step.handles.regions().iter().zip(&step.roles) {
        let role = if *role == Role::Fixed { VertexRole::Fixed } else { VertexRole::Handle };
        for &v in &region.vertices {
            if let Some(slot) = roles.get_mut(v as usize) {
                *slot = role;
            }
        }
    }
    roles
}

/// The positions the row's camera frames: the rest shape and every step's handle targets applied to
/// the rest shape (a `hold` step's targets are then rest positions, already framed; the actual
/// targets of later steps start from each method's own result, which the frame must not depend on).
fn frame_targets(scenario: &LoadedScenario) -> Vec<Vec<[f64; 3]>> {
    let rest = scenario.mesh.positions();
    scenario.steps.iter().filter_map(|s| s.targets(rest).ok()).map(|t| t.positions().to_vec()).collect()
}

/// Whether a finite vertex of `positions` falls outside the `CELL_SIZE` square seen by `camera`.
fn leaves_frame(camera: &Camera, positions: &[[f64; 3]]) -> bool {
    let size = CELL_SIZE as f64;
    positions.iter().filter(|p| p.iter().all(|c| c.is_finite())).any(|&p| {
        let [x, y, _] = camera.project(p, CELL_SIZE, CELL_SIZE);
        !(0.0..=size).contains(&x) || !(0.0..=size).contains(&y)
    })
}

fn render_row(row: &Row) -> RenderedRow {
    let mesh = &row.scenario.mesh;
    let (rest, triangles) = (mesh.positions(), mesh.triangles());
    let targets = frame_targets(row.scenario);
    let up = row.scenario.spec.up.map_or(2, |a| a.index());
    let camera =
        Camera::for_shapes_up(std::iter::once(rest).chain(targets.iter().map(Vec::as_slice)), 1.0, up);
    let roles = vertex_roles(row.scenario);
    let draw = |positions: &[[f64; 3]], paints: &[Paint]| {
        render(&camera, positions, triangles, CELL_SIZE, CELL_SIZE, paints)
    };
    let rest_image = draw(rest, &[Paint::Roles(&roles)])
        .pop()
        .unwrap_or_else(|| RgbImage::filled(CELL_SIZE, CELL_SIZE, [255; 3]));
    let cells = row
        .cases
        .par_iter()
        .map(|case| {
            let Some(case) = case else { return Cell::NotRun };
            let Some(positions) = usable_positions(case, row.scenario) else { return Cell::Failed };
            let errors = vertex_angle_errors(rest, positions, triangles);
            let areas = vertex_area_distortion(rest, positions, triangles);
            let paints = [Paint::Roles(&roles), Paint::Heat(&errors), Paint::Area(&areas)];
            let mut images = draw(positions, &paints).into_iter();
            let clipped = leaves_frame(&camera, positions);
            match (images.next(), images.next(), images.next()) {
                (Some(shaded), Some(heat), Some(area)) => Cell::Rendered { shaded, heat, area, clipped },
                _ => Cell::Failed,
            }
        })
        .collect();
    RenderedRow { rest: rest_image, cells }
}

/// Where the parts of a grid sit, in pixels.
struct GridLayout {
    /// Width of the row labels' column.
    label_w: u32,
    /// Height of a row: a cell, its caption and the gap.
    row_h: u32,
    width: u32,
    height: u32,
    /// Height of the legend above the notes.
    legend_h: u32,
    /// Top of the footer (legend and notes).
    footer: i64,
}

impl GridLayout {
    fn new(label_w: u32, columns: usize, rows: usize, kind: Kind, note_lines: usize) -> GridLayout {
        let row_h = CELL_SIZE + CAPTION_H + ROW_GAP;
        let width = 2 * PAD + label_w + (columns as u32 + 1) * CELL_SIZE;
        let legend_h = LEGEND_H[(kind != Kind::Shaded) as usize];
        let body = PAD + HEADER_H + rows.max(1) as u32 * row_h;
        let height = body + PAD + legend_h + note_lines as u32 * NOTE_LINE_H;
        GridLayout { label_w, row_h, width, height, legend_h, footer: body as i64 + 8 }
    }

    /// Left of column `c` (0: `rest`).
    fn cell_x(&self, c: u32) -> i64 {
        (PAD + self.label_w + c * CELL_SIZE) as i64
    }

    /// Top of row `r`.
    fn cell_y(&self, r: u32) -> i64 {
        (PAD + HEADER_H + r * self.row_h) as i64
    }
}

/// The grid of `kind`: a header of column names, one row per scenario (label, `rest` render, one
/// cell per column with its `E_theta / E_phi` caption), and a legend.
fn grid_image(
    rows: &[Row],
    rendered: &[RenderedRow],
    columns: &[String],
    kind: Kind,
) -> Result<RgbImage, String> {
    let label_w = row_label_width(rows)?;
    let notes = grid_notes(kind, 2 * PAD + label_w + (columns.len() as u32 + 1) * CELL_SIZE)?;
    let layout = GridLayout::new(label_w, columns.len(), rows.len(), kind, notes.len());
    let mut image = RgbImage::filled(layout.width, layout.height, [255; 3]);
    let mut labels = column_names(&layout, columns)?;
    image.fill_rect(PAD as i64, (PAD + HEADER_H - 4) as i64, layout.width - 2 * PAD, 1, RULE);
    if rows.is_empty() {
        let at = (layout.cell_x(0) as f64 + 8.0, layout.cell_y(0) as f64 + 40.0);
        labels.push(Label::new("no results", CAPTION_PX, MUTED, at, Align::Left));
    }
    for (r, (row, images)) in rows.iter().zip(rendered).enumerate() {
        draw_grid_row(&mut image, &mut labels, &layout, r as u32, row, images, kind);
        if r + 1 < rows.len() {
            let y = layout.cell_y(r as u32) + (CELL_SIZE + CAPTION_H + ROW_GAP / 2) as i64;
            image.fill_rect(PAD as i64, y, layout.width - 2 * PAD, 1, RULE);
        }
    }
    draw_footer(&mut image, &mut labels, &layout, kind, notes);
    draw_labels(&mut image, &labels)?;
    Ok(image)
}

/// The width of the row labels' column: the widest row name (or the mesh source line), at least
/// 120 pixels, and a margin.
fn row_label_width(rows: &[Row]) -> Result<u32, String> {
    let widest = rows
        .iter()
        .map(|r| {
            let name = r.label.as_deref().unwrap_or(&r.scenario.spec.name);
            Label::new(name, NAME_PX, INK, (0.0, 0.0), Align::Left).width()
        })
        .chain([Label::new("procedural look-alike", DETAIL_PX, INK, (0.0, 0.0), Align::Left).width()])
        .try_fold(120.0f64, |w, l| l.map(|l| w.max(l)))?;
    Ok(widest.ceil() as u32 + 24)
}

/// The notes under a grid of `kind` (how it was drawn, what its captions mean), wrapped to `width`.
fn grid_notes(kind: Kind, width: u32) -> Result<Vec<String>, String> {
    let mut notes = vec![
        format!(
            "Orthographic view from ({}, {}, {}), z up (axes turned for a scenario with another `up`); one camera per row, framing the rest shape and the \
             handle targets. A result that leaves that frame is drawn clipped and its cell marked \"clipped\"; \
             a suspect case is marked \"suspect\" (reasons in the results table). Headlight Lambert shading.",
            VIEW_FROM[0], VIEW_FROM[1], VIEW_FROM[2]
        ),
        if kind == Kind::Area {
            "e_area: RMS over faces of ln(A / A\u{2070}), the area distortion (0 when areas are kept).".to_string()
        } else {
            "E\u{3b8} / E\u{3c6}: RMS change of the corner / dihedral angles over the whole mesh (degrees)."
                .to_string()
        },
    ];
    if kind != Kind::Shaded {
        notes.push("Rest column: fixed vertices blue, handle vertices orange.".to_string());
    }
    let lines =
        notes.iter().map(|n| wrap(n, DETAIL_PX, (width - 2 * PAD) as f64)).collect::<Result<Vec<_>, _>>()?;
    Ok(lines.concat())
}

/// The header's labels: `rest` and the column names, a long name set smaller rather than run into
/// its neighbours.
fn column_names(layout: &GridLayout, columns: &[String]) -> Result<Vec<Label>, String> {
    let mut labels = Vec::new();
    for (c, name) in std::iter::once("rest").chain(columns.iter().map(String::as_str)).enumerate() {
        let x = layout.cell_x(c as u32) as f64 + CELL_SIZE as f64 / 2.0;
        let mut label = Label::new(name, NAME_PX, INK, (x, (PAD + HEADER_H - 16) as f64), Align::Center);
        let room = (CELL_SIZE - 16) as f64;
        label.size *= (room / label.width()?).min(1.0);
        labels.push(label);
    }
    Ok(labels)
}

/// Row `r`: its label (name, size, mesh source), the rest render and a cell per column.
fn draw_grid_row(
    image: &mut RgbImage,
    labels: &mut Vec<Label>,
    layout: &GridLayout,
    r: u32,
    row: &Row,
    images: &RenderedRow,
    kind: Kind,
) {
    let top = layout.cell_y(r);
    let mid = (top + CELL_SIZE as i64 / 2) as f64;
    let scenario = row.scenario;
    let name = row.label.as_deref().unwrap_or(&scenario.spec.name);
    labels.push(Label::new(name, NAME_PX, INK, (PAD as f64, mid - 6.0), Align::Left));
    let size = format!("{} vertices", scenario.mesh.n_vertices());
    labels.push(Label::new(size, DETAIL_PX, MUTED, (PAD as f64, mid + 20.0), Align::Left));
    labels.push(Label::new(&scenario.mesh_source, DETAIL_PX, MUTED, (PAD as f64, mid + 42.0), Align::Left));
    image.paste(&images.rest, layout.cell_x(0), top);
    for (c, (case, cell)) in row.cases.iter().zip(&images.cells).enumerate() {
        draw_cell(image, labels, (layout.cell_x(c as u32 + 1), top), *case, cell, kind);
    }
}

/// The cell at `(x, top)`: `not run`, `failed`, or the result's picture of `kind` with its marks
/// and caption.
fn draw_cell(
    image: &mut RgbImage,
    labels: &mut Vec<Label>,
    (x, top): (i64, i64),
    case: Option<&CaseResult>,
    cell: &Cell,
    kind: Kind,
) {
    let (centre, mid) = (x as f64 + CELL_SIZE as f64 / 2.0, (top + CELL_SIZE as i64 / 2) as f64);
    match cell {
        Cell::NotRun => {
            image.fill_rect(x + 6, top + 6, CELL_SIZE - 12, CELL_SIZE - 12, EMPTY_CELL);
            labels.push(Label::new("not run", CAPTION_PX, FAINT, (centre, mid + 6.0), Align::Center));
        }
        Cell::Failed => {
            image.fill_rect(x + 6, top + 6, CELL_SIZE - 12, CELL_SIZE - 12, FAILED_CELL);
            labels.push(Label::new("failed", NAME_PX, FAILED_INK, (centre, mid + 7.0), Align::Center));
        }
        Cell::Rendered { shaded, heat, area, clipped } => {
            let picture = match kind {
                Kind::Shaded => shaded,
                Kind::Heat => heat,
                Kind::Area => area,
            };
            image.paste(picture, x, top);
            let marks = cell_marks(case, *clipped);
            if let Some((_, color)) = marks.first() {
                image.outline_rect(x + 2, top + 2, CELL_SIZE - 4, CELL_SIZE - 4, 3, *color);
            }
            for (i, (text, color)) in marks.iter().enumerate() {
                let at = (centre, (top + 28 + 24 * i as i64) as f64);
                labels.push(Label::new(*text, DETAIL_PX, *color, at, Align::Center));
            }
            if let Some(case) = case {
                let at = (centre, (top + CELL_SIZE as i64 + 27) as f64);
                labels.push(match kind {
                    Kind::Area => area_caption(case.metric(Metric::EArea), at),
                    _ => error_caption(case.metric(Metric::ETheta), case.metric(Metric::EPhi), at),
                });
            }
        }
    }
}

/// The marks on a rendered cell, the first one's colour outlining it: clipped, unfinished, suspect.
fn cell_marks(case: Option<&CaseResult>, clipped: bool) -> Vec<(&'static str, [u8; 3])> {
    let mut marks = Vec::new();
    if clipped {
        marks.push(("clipped: leaves the frame", FAILED_INK));
    }
    if case.is_some_and(|c| c.status.is_unfinished()) {
        marks.push(("unfinished: stopped at its cap", UNFINISHED_INK));
    }
    if case.is_some_and(|c| c.status.shape_reasons().next().is_some()) {
        marks.push(("suspect", SUSPECT_INK));
    }
    marks
}

/// The legend of `kind` and the notes under the rows.
fn draw_footer(
    image: &mut RgbImage,
    labels: &mut Vec<Label>,
    layout: &GridLayout,
    kind: Kind,
    notes: Vec<String>,
) {
    let footer = layout.footer;
    match kind {
        Kind::Shaded => role_legend(image, labels, PAD as i64, footer),
        Kind::Heat => heat_legend(image, labels, PAD as i64, footer),
        Kind::Area => area_legend(image, labels, PAD as i64, footer),
    }
    for (i, line) in notes.into_iter().enumerate() {
        let y = footer + (layout.legend_h + (i as u32 + 1) * NOTE_LINE_H) as i64 - 8;
        labels.push(Label::new(line, DETAIL_PX, MUTED, (PAD as f64, y as f64), Align::Left));
    }
}

/// "E_θ x.xx° / E_φ y.yy°" centred at `(x, baseline)`.
fn error_caption(e_theta: f64, e_phi: f64, at: (f64, f64)) -> Label {
    let value = |v: f64| if v.is_finite() { format!(" {v:.2}\u{b0}") } else { " n/a".to_string() };
    let (theta, phi) = (value(e_theta), value(e_phi));
    let spans = [
        ("E", false),
        ("\u{3b8}", true),
        (&theta, false),
        ("  /  E", false),
        ("\u{3c6}", true),
        (&phi, false),
    ];
    Label::rich(&spans, CAPTION_PX, INK, at, Align::Center)
}

/// "e_area x.xxx" centred at `(x, baseline)`.
fn area_caption(e_area: f64, at: (f64, f64)) -> Label {
    let value = if e_area.is_finite() { format!("e_area {e_area:.3}") } else { "e_area n/a".to_string() };
    Label::new(value, CAPTION_PX, INK, at, Align::Center)
}

/// Swatches of the vertex roles, at `(x, y)` (top-left).
fn role_legend(image: &mut RgbImage, labels: &mut Vec<Label>, x: i64, y: i64) {
    let mut left = x;
    for (role, name) in
        [(VertexRole::Fixed, "fixed"), (VertexRole::Handle, "handle"), (VertexRole::Free, "free")]
    {
        image.fill_rect(left, y + 8, 20, 20, role.color().map(|c| (255.0 * c).round() as u8));
        labels.push(Label::new(name, LEGEND_PX, INK, ((left + 28) as f64, (y + 25) as f64), Align::Left));
        left += 120;
    }
}

/// A colour bar under `title` at `(x, y)` (top-left): `color_at(t)` for `t` from 0 (left) to 1
/// (right), and a tick with its label at each `(t, text)` of `ticks`.
fn color_bar(
    image: &mut RgbImage,
    labels: &mut Vec<Label>,
    (x, y): (i64, i64),
    title: &str,
    color_at: impl Fn(f64) -> [f64; 3],
    ticks: &[(f64, String)],
) {
    const BAR_W: u32 = 360;
    const BAR_H: u32 = 16;
    labels.push(Label::new(title, LEGEND_PX, INK, (x as f64, (y + 22) as f64), Align::Left));
    let bar_y = y + 32;
    for i in 0..BAR_W {
        let color = color_at((i as f64 + 0.5) / BAR_W as f64).map(|c| (255.0 * c).round() as u8);
        image.fill_rect(x + i as i64, bar_y, 1, BAR_H, color);
    }
    for (t, text) in ticks {
        let tx = x + (t * (BAR_W - 1) as f64).round() as i64;
        image.fill_rect(tx, bar_y + BAR_H as i64, 1, 5, INK);
        let at = (tx as f64, (bar_y + BAR_H as i64 + 22) as f64);
        labels.push(Label::new(text.as_str(), TICK_PX, INK, at, Align::Center));
    }
}

/// The heat colour bar `0..HEAT_MAX_DEG` under its title, with ticks, at `(x, y)` (top-left).
fn heat_legend(image: &mut RgbImage, labels: &mut Vec<Label>, x: i64, y: i64) {
    let ticks: Vec<(f64, String)> = (0..=5)
        .map(|t| {
            let degrees = HEAT_MAX_DEG * t as f64 / 5.0;
            // The top colour stands for everything above the scale.
            let text = if t == 5 { format!("\u{2265}{degrees}\u{b0}") } else { format!("{degrees}\u{b0}") };
            (t as f64 / 5.0, text)
        })
        .collect();
    let title = "Per-vertex RMS change of the corner angles (degrees), one scale for all cells";
    color_bar(image, labels, (x, y), title, |t| heat_color(t * HEAT_MAX_DEG), &ticks);
}

/// The diverging area colour bar `±AREA_MAX_LOG` under its title, ticks as area factors, at
/// `(x, y)` (top-left).
fn area_legend(image: &mut RgbImage, labels: &mut Vec<Label>, x: i64, y: i64) {
    let ticks: Vec<(f64, String)> = (0..=4)
        .map(|t| {
            let factor = (AREA_MAX_LOG * (t as f64 / 2.0 - 1.0)).exp();
            let text = match t {
                0 => format!("\u{2264}\u{d7}{factor:.2}"),
                4 => format!("\u{2265}\u{d7}{factor:.2}"),
                _ => format!("\u{d7}{factor:.2}"),
            };
            (t as f64 / 4.0, text)
        })
        .collect();
    let title = "Per-vertex area change A / A\u{2070} of the one-ring (log scale), one scale for all cells";
    color_bar(image, labels, (x, y), title, |t| area_color((2.0 * t - 1.0) * AREA_MAX_LOG), &ticks);
}

/// `text` broken at spaces into lines at most `max_width` pixels wide at font size `size` (a word
/// longer than that gets a line of its own).
fn wrap(text: &str, size: f64, max_width: f64) -> Result<Vec<String>, String> {
    let mut lines: Vec<String> = Vec::new();
    for word in text.split(' ').filter(|w| !w.is_empty()) {
        match lines.last_mut() {
            Some(line)
                if Label::new(format!("{line} {word}"), size, INK, (0.0, 0.0), Align::Left).width()?
                    <= max_width =>
            {
                line.push(' ');
                line.push_str(word);
            }
            _ => lines.push(word.to_string()),
        }
    }
    Ok(lines)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::{LoadedStep, Motion, ScenarioSpec};
    use meshes::shapes::{generate, ShapeKind};
    use meshes::{AffineTransform, Topology, VertexStatus};
    use methods::{HandleRegion, HandleSet};

    /// A procedural cylinder with the survey's fixed and handle regions.
    fn scenario(name: &str) -> LoadedScenario {
        let shape = generate(ShapeKind::Cylinder, 800).unwrap();
        let of = |status: VertexStatus| {
            shape.selection.iter().enumerate().filter(|(_, s)| **s == status).map(|(v, _)| v as u32).collect()
        };
        let regions = vec![
            HandleRegion { name: "fixed".into(), vertices: of(VertexStatus::Fixed) },
            HandleRegion { name: "handle".into(), vertices: of(VertexStatus::Handle) },
        ];
        let handles = HandleSet::new(regions, shape.mesh.n_vertices()).unwrap();
        let spec = ScenarioSpec { name: name.into(), ..Default::default() };
        LoadedScenario {
            spec,
            mesh_source: "procedural look-alike".into(),
            topology: Topology::new(&shape.mesh).unwrap(),
            mesh: shape.mesh,
            steps: vec![LoadedStep {
                handles,
                motions: vec![Motion::Hold, Motion::Transform(shape.transform)],
                roles: vec![Role::Fixed, Role::Handle],
            }],
            input: None,
            notes: Vec::new(),
            member: None,
            repaired: None,
        }
    }

    fn case(scenario: &str, method: &str, status: &str, positions: Option<Vec<[f64; 3]>>) -> CaseResult {
        let mut c = CaseResult::empty(scenario, method, "procedural look-alike", 0, 0);
        c.quality.set(Metric::ETheta, Some(1.234));
        c.quality.set(Metric::EArea, Some(0.05));
        c.status = status.parse().unwrap();
        c.positions = positions;
        c
    }

    /// Scenario `tiny`: `laplacian` bent, `odd/name` with a NaN vertex, `arap` failed; scenario
    /// `other`: `arap` only, its shape too short (a broken result); scenario `unused`: no results.
    fn inputs() -> (Vec<CaseResult>, Vec<LoadedScenario>) {
        let scenarios = vec![scenario("tiny"), scenario("other"), scenario("unused")];
        let rest = scenarios[0].mesh.positions();
        let bend = AffineTransform::rotation_about([0.0, 1.0, 0.0], 0.6, [0.0, 0.0, 0.0]);
        let bent: Vec<[f64; 3]> = rest.iter().map(|&p| if p[2] > 6.0 { bend.apply(p) } else { p }).collect();
        let mut with_nan = rest.to_vec();
        with_nan[3] = [f64::NAN; 3];
        let results = vec![
            case("tiny", "laplacian", "ok", Some(bent)),
            case("tiny", "arap", "failed: diverged", None),
            case("tiny", "odd/name", "ok", Some(with_nan)),
            case("other", "arap", "ok", Some(rest[..10].to_vec())),
        ];
        (results, scenarios)
    }

    /// The paths of `images`, and that each is in the group its name says.
    fn paths(images: Vec<Image>) -> Vec<PathBuf> {
        for i in &images {
            let name = i.path.file_name().unwrap().to_string_lossy();
            let group = if name.starts_with("grid") {
                ImageGroup::Grid
            } else if name.starts_with("worst-") {
                ImageGroup::Dataset
            } else {
                ImageGroup::Render
            };
            assert_eq!(i.group, group, "{name}");
        }
        images.into_iter().map(|i| i.path).collect()
    }

    fn decode(path: &Path) -> image::RgbImage {
        image::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).to_rgb8()
    }

    #[test]
    fn write_figures_writes_every_expected_file_deterministically() {
        let (results, scenarios) = inputs();
        let dirs = [tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap()];
        let written = paths(write_figures(dirs[0].path(), &results, &scenarios).unwrap());
        let expected = [
            "tiny-rest.png",
            "tiny-laplacian.png",
            "tiny-laplacian-heat.png",
            "tiny-laplacian-area.png",
            "tiny-odd_name.png",
            "tiny-odd_name-heat.png",
            "tiny-odd_name-area.png",
            "other-rest.png",
            "grid.png",
            "grid_heat.png",
            "grid_area.png",
        ];
        let expected: Vec<PathBuf> = expected.iter().map(|f| Path::new("figures").join(f)).collect();
        assert_eq!(written, expected);
        let mut on_disk: Vec<String> = std::fs::read_dir(dirs[0].path().join("figures"))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        on_disk.sort();
        let mut names: Vec<String> =
            expected.iter().map(|p| p.file_name().unwrap().to_string_lossy().into()).collect();
        names.sort();
        assert_eq!(on_disk, names, "nothing else, no temporary files left");
        for path in &written {
            let image = decode(&dirs[0].path().join(path));
            if !path.file_name().unwrap().to_string_lossy().starts_with("grid") {
                assert_eq!(image.dimensions(), (CELL_SIZE, CELL_SIZE), "{}", path.display());
            }
        }
        // Columns: rest + laplacian, arap (registry order) + odd/name; rows: tiny, other.
        let grid = decode(&dirs[0].path().join("figures/grid.png"));
        assert!(grid.width() > 4 * CELL_SIZE && grid.width() < 5 * CELL_SIZE, "{}", grid.width());
        assert!(grid.height() > 2 * CELL_SIZE && grid.height() < 3 * CELL_SIZE, "{}", grid.height());
        let heat = decode(&dirs[0].path().join("figures/grid_heat.png"));
        assert_eq!(heat.width(), grid.width());
        assert!(heat.height() > grid.height(), "the colour bar takes more room than the swatches");

        assert_eq!(paths(write_figures(dirs[1].path(), &results, &scenarios).unwrap()), written);
        for path in &written {
            let bytes = |d: &tempfile::TempDir| std::fs::read(d.path().join(path)).unwrap();
            assert!(bytes(&dirs[0]) == bytes(&dirs[1]), "{} differs between runs", path.display());
        }
    }

    #[test]
    fn renders_show_the_regions_and_the_heat_map_the_bend() {
        let (results, scenarios) = inputs();
        let dir = tempfile::tempdir().unwrap();
        write_figures(dir.path(), &results, &scenarios).unwrap();
        let count = |image: &image::RgbImage, role: VertexRole| {
            let [r, g, b] = role.color();
            // Same hue under any shading: compare colour ratios.
            image
                .pixels()
                .filter(|p| {
                    let [pr, pg, pb] = p.0.map(|c| c as f64 + 1.0);
                    (pr / pb - (r + 0.004) / (b + 0.004)).abs() < 0.15 * (r / b).max(1.0)
                        && (pg / pb - (g + 0.004) / (b + 0.004)).abs() < 0.15 * (g / b).max(1.0)
                        && p.0 != [255; 3]
                })
                .count()
        };
        let rest = decode(&dir.path().join("figures/tiny-rest.png"));
        assert!(count(&rest, VertexRole::Fixed) > 100, "fixed region visible");
        assert!(count(&rest, VertexRole::Handle) > 100, "handle region visible");
        let background = rest.pixels().filter(|p| p.0 == [255; 3]).count();
        assert!(background > 1000 && background < (CELL_SIZE * CELL_SIZE) as usize * 9 / 10);
        // The bend changes corner angles only where the cylinder is cut at z = 6: hot pixels exist,
        // and most of the surface stays at the cold end of the scale.
        let heat = decode(&dir.path().join("figures/tiny-laplacian-heat.png"));
        let red = heat.pixels().filter(|p| p.0[0] > 150 && p.0[2] < 90).count();
        let blue = heat.pixels().filter(|p| p.0[2] > p.0[0] + 40).count();
        assert!(red > 10 && blue > 10 * red, "red {red}, blue {blue}");
        let undeformed = decode(&dir.path().join("figures/tiny-odd_name-heat.png"));
        assert_eq!(undeformed.pixels().filter(|p| p.0[0] > 150 && p.0[2] < 90).count(), 0);
    }

    #[test]
    fn no_results_still_give_every_grid() {
        let dir = tempfile::tempdir().unwrap();
        let written = paths(write_figures(dir.path(), &[], &[scenario("unused")]).unwrap());
        assert_eq!(
            written,
            [
                Path::new("figures/grid.png"),
                Path::new("figures/grid_heat.png"),
                Path::new("figures/grid_area.png")
            ]
        );
        assert!(written.iter().all(|p| dir.path().join(p).is_file()));
    }

    #[test]
    fn a_runaway_result_leaves_the_rest_picture_unchanged_and_is_marked_clipped() {
        let (results, scenarios) = inputs();
        let rest = scenarios[0].mesh.positions();
        let diagonal = scenarios[0].mesh.bbox_diagonal();
        // 30 diagonals away, as the diverged `hirm` of issue 14 was.
        let far: Vec<[f64; 3]> =
            rest.iter().map(|p| [p[0] + 30.0 * diagonal, p[1], p[2] - 5.0 * diagonal]).collect();
        let mut with_runaway = results.clone();
        with_runaway.push(case("tiny", "hirm", "suspect: leaves its frame", Some(far)));
        let dirs = [tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap()];
        write_figures(dirs[0].path(), &results, &scenarios).unwrap();
        let written = paths(write_figures(dirs[1].path(), &with_runaway, &scenarios).unwrap());
        for name in ["tiny-rest.png", "tiny-laplacian.png", "tiny-laplacian-heat.png"] {
            let bytes = |d: &tempfile::TempDir| std::fs::read(d.path().join("figures").join(name)).unwrap();
            assert!(
                bytes(&dirs[0]) == bytes(&dirs[1]),
                "{name} changed when a runaway result joined its row"
            );
        }
        // The runaway result is entirely outside the frame: its picture is blank.
        assert!(written.contains(&Path::new("figures").join("tiny-hirm.png")));
        let runaway = decode(&dirs[1].path().join("figures/tiny-hirm.png"));
        assert!(runaway.pixels().all(|p| p.0 == [255; 3]), "clipped away");
        // Its grid cell carries the red frame of a clipped cell; the same cell without it does not exist.
        let camera = Camera::for_shapes([rest], 1.0);
        let targets = frame_targets(&scenarios[0]);
        assert!(!targets.is_empty());
        let framed = Camera::for_shapes(std::iter::once(rest).chain(targets.iter().map(Vec::as_slice)), 1.0);
        assert!(leaves_frame(&framed, &with_runaway.last().unwrap().positions.clone().unwrap()));
        assert!(!leaves_frame(&framed, rest));
        assert!(!leaves_frame(&camera, rest));
        let grid = decode(&dirs[1].path().join("figures/grid.png"));
        let red = grid.pixels().filter(|p| p.0 == FAILED_INK).count();
        assert!(red > 4 * (CELL_SIZE as usize - 4), "the clipped cell is outlined: {red} red pixels");
    }

    #[test]
    fn an_unfinished_case_is_outlined_in_its_own_colour() {
        let (results, scenarios) = inputs();
        let rest = scenarios[0].mesh.positions().to_vec();
        let mut with_unfinished = results.clone();
        with_unfinished.push(case(
            "tiny",
            "hirm",
            "unfinished: stopped at the 500-iteration cap, last step 3.0e-4 of the diagonal",
            Some(rest),
        ));
        let dir = tempfile::tempdir().unwrap();
        write_figures(dir.path(), &with_unfinished, &scenarios).unwrap();
        let grid = decode(&dir.path().join("figures/grid.png"));
        let blue = grid.pixels().filter(|p| p.0 == UNFINISHED_INK).count();
        assert!(blue > 4 * (CELL_SIZE as usize - 4), "the unfinished cell is outlined: {blue} pixels");
        let dir = tempfile::tempdir().unwrap();
        write_figures(dir.path(), &results, &scenarios).unwrap();
        let grid = decode(&dir.path().join("figures/grid.png"));
        assert_eq!(grid.pixels().filter(|p| p.0 == UNFINISHED_INK).count(), 0);
    }

    #[test]
    fn notes_wrap_at_spaces_within_the_width() {
        crate::report::fonts::register_sans_serif().unwrap();
        let text = "one two three four five six seven eight nine ten";
        let lines = wrap(text, DETAIL_PX, 120.0).unwrap();
        assert!(lines.len() > 2, "{lines:?}");
        assert_eq!(lines.join(" "), text);
        for line in &lines {
            assert!(
                Label::new(line.as_str(), DETAIL_PX, INK, (0.0, 0.0), Align::Left).width().unwrap() <= 120.0
            );
        }
        assert_eq!(wrap(text, DETAIL_PX, 1e6).unwrap(), [text]);
        assert_eq!(wrap("", DETAIL_PX, 10.0).unwrap(), Vec::<String>::new());
    }

    #[test]
    fn file_names_keep_safe_characters_only() {
        assert_eq!(crate::stored_report::file_name("bar-sweep_6k.v2"), "bar-sweep_6k.v2");
        assert_eq!(crate::stored_report::file_name("a/b c\\d"), "a_b_c_d");
        assert_eq!(crate::stored_report::file_name(".."), "_..");
        assert_eq!(crate::stored_report::file_name(""), "_");
    }
}
