//! The HTML renderer of [`Document`]s, [`Table`]s and [`Image`]s: the page's sections
//! ([`crate::report::html`]) show the reports through it.
//!
//! Text is escaped, code spans are `<code>`; a paragraph is a `<p>`; a list is a `<p>` per item,
//! marked `- ` as in the `.md` files (how the page has always shown them); a table is its caption
//! as a `<p>`, then a `<table>` of a `<th>` header row and `<td>` rows.

use std::fmt::Write as _;
use std::path::Path;

use super::{Block, Document, Image, Span, Table, Text};

/// Escape text for HTML element content and attribute values.
pub fn escape(text: &str) -> String {
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// `document` as HTML.
pub fn document(document: &Document) -> String {
    document.blocks.iter().map(block).collect()
}

/// One block.
pub fn block(block: &Block) -> String {
    match block {
        Block::Heading { level, text: title } => format!("<h{level}>{}</h{level}>\n", text(title)),
        Block::Paragraph(paragraph) => format!("<p>{}</p>\n", text(paragraph)),
        Block::List(items) => items.iter().map(|item| format!("<p>- {}</p>\n", text(item))).collect(),
        Block::Table(t) => table(t),
    }
}

/// A table with its caption above it.
pub fn table(table: &Table) -> String {
    let mut out = table.caption.as_ref().map_or(String::new(), |c| format!("<p>{}</p>\n", text(c)));
    out.push_str("<table>\n");
    out.push_str(&row("th", table.header.iter().map(|c| &c.title)));
    for cells in &table.rows {
        out.push_str(&row("td", cells.iter()));
    }
    out.push_str("</table>\n");
    out
}

/// `<tr>` of `tag` cells and a newline.
fn row<'a>(tag: &str, cells: impl Iterator<Item = &'a Text>) -> String {
    let mut out = String::from("<tr>");
    for cell in cells {
        let _ = write!(out, "<{tag}>{}</{tag}>", text(cell));
    }
    out.push_str("</tr>\n");
    out
}

/// Inline text, escaped, code spans as `<code>`.
pub fn text(text: &Text) -> String {
    text.0
        .iter()
        .map(|span| match span {
            Span::Plain(s) => escape(s),
            Span::Code(s) => format!("<code>{}</code>", escape(s)),
        })
        .collect()
}

/// `image` as a figure: the PNG, linked to itself, its caption and a link to the SVG beside it.
pub fn figure(image: &Image) -> String {
    let url = link(&image.path);
    let svg = image.path.with_extension("svg");
    format!(
        "<figure><a href=\"{u}\"><img src=\"{u}\" alt=\"{c}\" loading=\"eager\"></a><figcaption>{c} \
         (<a href=\"{s}\">SVG</a>)</figcaption></figure>\n",
        u = escape(&url),
        c = escape(&image.caption),
        s = escape(&link(&svg)),
    )
}

/// A path relative to the report directory as a URL path (forward slashes).
pub fn link(path: &Path) -> String {
    path.components().map(|c| c.as_os_str().to_string_lossy().into_owned()).collect::<Vec<_>>().join("/")
}

#[cfg(test)]
mod tests {
    use super::super::Column;
    use super::*;

    #[test]
    fn text_is_escaped_and_code_spans_become_code_elements() {
        let t = Text::plain("a < b, ").then_code("x&y").then(" \"q\"");
        assert_eq!(text(&t), "a &lt; b, <code>x&amp;y</code> &quot;q&quot;");
    }

    #[test]
    fn a_table_is_its_caption_then_a_header_row_and_rows() {
        let mut t = Table::with_columns(vec![Column::left("name"), Column::right("n")]).captioned("See ");
        t.caption = t.caption.map(|c| c.then_code("x"));
        t.push_row(["a", "1"]);
        assert_eq!(
            table(&t),
            "<p>See <code>x</code></p>\n<table>\n<tr><th>name</th><th>n</th></tr>\n<tr><td>a</td><td>1</td></tr>\n</table>\n"
        );
    }

    #[test]
    fn list_items_are_paragraphs_marked_as_in_markdown() {
        let mut doc = Document::default();
        doc.heading(3, "h");
        doc.list(vec![Text::plain("one"), Text::code("two")]);
        assert_eq!(doc.to_html(), "<h3>h</h3>\n<p>- one</p>\n<p>- <code>two</code></p>\n");
    }
}
