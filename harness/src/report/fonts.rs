//! The TrueType font that plots and figure labels are drawn with, loaded at run time so that the
//! build needs no fontconfig or freetype. Text goes through plotters' `ab_glyph` backend under the
//! family name `sans-serif`.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use crate::error::HarnessError;

/// Environment variable naming a `.ttf` file to use instead of the system font.
pub const FONT_ENV: &str = "DEFORM_FONT";

/// Where Debian (fonts-dejavu-core), Arch/Fedora and others put a sans-serif TrueType font.
const CANDIDATES: &[&str] = &[
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu-sans-fonts/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
];

/// Register the font as `sans-serif` (once per process) and return its path.
pub fn register_sans_serif() -> Result<&'static Path, HarnessError> {
    static REGISTERED: OnceLock<Result<PathBuf, String>> = OnceLock::new();
    REGISTERED.get_or_init(load).as_deref().map_err(|message| HarnessError::Report(message.clone()))
}

fn load() -> Result<PathBuf, String> {
    let chosen = match std::env::var_os(FONT_ENV) {
        Some(path) => PathBuf::from(path),
        None => CANDIDATES.iter().map(PathBuf::from).find(|p| p.is_file()).ok_or_else(|| {
            format!(
                "no TrueType font for plots and figures: none of {} exists; install Debian's \
                 fonts-dejavu-core or set {FONT_ENV} to a .ttf file",
                CANDIDATES.join(", ")
            )
        })?,
    };
    let bytes = std::fs::read(&chosen).map_err(|e| format!("{}: {e}", chosen.display()))?;
    // plotters keeps fonts for the life of the process; this runs once.
    let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
    for style in [plotters::style::FontStyle::Normal, plotters::style::FontStyle::Bold] {
        plotters::style::register_font("sans-serif", style, bytes)
            .map_err(|_| format!("{}: not a TrueType/OpenType font", chosen.display()))?;
    }
    Ok(chosen)
}
