//! What the report writers hand on: [`Text`] (plain runs and code spans), [`Table`]s, [`Image`]s and
//! [`Document`]s (a sequence of [`Block`]s: headings, paragraphs, lists, tables). A `.md` report is
//! a document rendered by [`markdown`]; the page renders the same values with [`html`]. One
//! renderer each way, and nothing parses Markdown back.

pub mod html;
pub mod markdown;

use std::path::{Path, PathBuf};

use crate::error::HarnessError;

/// A run of inline text.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Span {
    /// Text as it reads.
    Plain(String),
    /// A name to type or look up (a method, a file, an option): `` `x` `` in Markdown, `<code>` in
    /// HTML.
    Code(String),
}

/// Inline text: plain runs and code spans, in order.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Text(pub Vec<Span>);

impl Text {
    /// `text` as it reads.
    pub fn plain(text: impl Into<String>) -> Text {
        Text(vec![Span::Plain(text.into())])
    }

    /// `text` as a code span.
    pub fn code(text: impl Into<String>) -> Text {
        Text(vec![Span::Code(text.into())])
    }

    /// This text, then plain `text`.
    pub fn then(mut self, text: impl Into<String>) -> Text {
        self.0.push(Span::Plain(text.into()));
        self
    }

    /// This text, then `text` as a code span.
    pub fn then_code(mut self, text: impl Into<String>) -> Text {
        self.0.push(Span::Code(text.into()));
        self
    }

    /// Plain `prefix`, then this text.
    pub fn after(self, prefix: impl Into<String>) -> Text {
        let mut spans = vec![Span::Plain(prefix.into())];
        spans.extend(self.0);
        Text(spans)
    }
}

impl From<&str> for Text {
    fn from(text: &str) -> Text {
        Text::plain(text)
    }
}

impl From<String> for Text {
    fn from(text: String) -> Text {
        Text::plain(text)
    }
}

impl From<&String> for Text {
    fn from(text: &String) -> Text {
        Text::plain(text.as_str())
    }
}

/// How a column's cells sit (Markdown only: `---` or `---:`; the page's stylesheet sets its own).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Align {
    #[default]
    Left,
    Right,
}

/// A column of a [`Table`]: its title and how its cells sit.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Column {
    pub title: Text,
    pub align: Align,
}

impl Column {
    pub fn left(title: impl Into<Text>) -> Column {
        Column { title: title.into(), align: Align::Left }
    }

    pub fn right(title: impl Into<Text>) -> Column {
        Column { title: title.into(), align: Align::Right }
    }
}

/// A table: a caption (what it shows, printed above it), a header and rows of cells, each cell's
/// text already formatted (numbers with their digits and units decided by the writer).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Table {
    pub caption: Option<Text>,
    pub header: Vec<Column>,
    pub rows: Vec<Vec<Text>>,
}

impl Table {
    /// A table without rows under `titles`, every column left-aligned.
    pub fn new<T: Into<Text>>(titles: impl IntoIterator<Item = T>) -> Table {
        Table::with_columns(titles.into_iter().map(Column::left).collect())
    }

    /// A table without rows under `header`.
    pub fn with_columns(header: Vec<Column>) -> Table {
        Table { caption: None, header, rows: Vec::new() }
    }

    /// This table with `caption` above it.
    pub fn captioned(mut self, caption: impl Into<Text>) -> Table {
        self.caption = Some(caption.into());
        self
    }

    /// Add a row of `cells` (one per column).
    pub fn push_row<T: Into<Text>>(&mut self, cells: impl IntoIterator<Item = T>) {
        let row: Vec<Text> = cells.into_iter().map(Into::into).collect();
        debug_assert_eq!(row.len(), self.header.len(), "a row has a cell per column");
        self.rows.push(row);
    }
}

/// A part of a [`Document`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Block {
    /// A heading of `level` (1: the document's title).
    Heading {
        level: u8,
        text: Text,
    },
    Paragraph(Text),
    /// Items, one a line.
    List(Vec<Text>),
    Table(Table),
}

/// A report as a sequence of blocks (empty: nothing to report).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Document {
    pub blocks: Vec<Block>,
}

impl Document {
    pub fn is_empty(&self) -> bool {
        self.blocks.is_empty()
    }

    pub fn heading(&mut self, level: u8, text: impl Into<Text>) {
        self.blocks.push(Block::Heading { level, text: text.into() });
    }

    pub fn paragraph(&mut self, text: impl Into<Text>) {
        self.blocks.push(Block::Paragraph(text.into()));
    }

    pub fn list(&mut self, items: Vec<Text>) {
        self.blocks.push(Block::List(items));
    }

    pub fn table(&mut self, table: Table) {
        self.blocks.push(Block::Table(table));
    }

    /// The document as Markdown ([`markdown::document`]).
    pub fn to_markdown(&self) -> String {
        markdown::document(self)
    }

    /// The document as HTML ([`html::document`]).
    pub fn to_html(&self) -> String {
        html::document(self)
    }

    /// Write the document as Markdown to `path`, atomically.
    pub fn write_markdown(&self, path: &Path) -> Result<(), HarnessError> {
        write_text(path, &self.to_markdown())
    }
}

/// Write `text` to `path`, atomically.
pub(crate) fn write_text(path: &Path, text: &str) -> Result<(), HarnessError> {
    meshes::io::atomic_write(path, |w| w.write_all(text.as_bytes()).map_err(meshes::MeshError::from))
        .map_err(HarnessError::from)
}

/// Where the page shows an image.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ImageGroup {
    /// Across the dataset: the error distributions, the cost curves, each family's worst results.
    Dataset,
    /// Cost against size.
    SizeSeries,
    /// The rendered result grids.
    Grid,
    /// Every single render (rest shapes, results, heat and area maps).
    Render,
    /// Quality against time on the test named.
    QualityTime(String),
    /// The other plots.
    Plot,
}

/// A PNG the run wrote: its group on the page, its path relative to the report directory and its
/// caption.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Image {
    pub group: ImageGroup,
    pub path: PathBuf,
    pub caption: String,
}
