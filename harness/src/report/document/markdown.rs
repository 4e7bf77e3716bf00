//! The Markdown renderer of [`Document`]s: the `.md` reports.
//!
//! Blocks are separated by a blank line; a table is its caption, a blank line, the header, the
//! alignment row and the rows (`| a | b |`); a list is an item a line (`- item`).

use super::{Align, Block, Document, Span, Table, Text};

/// `document` as Markdown.
pub fn document(document: &Document) -> String {
    document.blocks.iter().map(block).collect::<Vec<_>>().join("\n")
}

/// One block, ending in a newline (an empty list: nothing).
pub fn block(block: &Block) -> String {
    match block {
        Block::Heading { level, text: title } => {
            format!("{} {}\n", "#".repeat(usize::from(*level)), text(title))
        }
        Block::Paragraph(paragraph) => format!("{}\n", text(paragraph)),
        Block::List(items) => items.iter().map(|item| format!("- {}\n", text(item))).collect(),
        Block::Table(t) => table(t),
    }
}

/// A table with its caption above it.
pub fn table(table: &Table) -> String {
    let mut out = table.caption.as_ref().map_or(String::new(), |c| format!("{}\n\n", text(c)));
    out.push_str(&row(table.header.iter().map(|c| &c.title)));
    out.push('|');
    for column in &table.header {
        out.push_str(match column.align {
            Align::Left => "---|",
            Align::Right => "---:|",
        });
    }
    out.push('\n');
    for cells in &table.rows {
        out.push_str(&row(cells.iter()));
    }
    out
}

/// `| a | b |` and a newline.
fn row<'a>(cells: impl Iterator<Item = &'a Text>) -> String {
    let mut out = String::from("|");
    for cell in cells {
        out.push(' ');
        out.push_str(&text(cell));
        out.push_str(" |");
    }
    out.push('\n');
    out
}

/// Inline text: code spans in backticks.
pub fn text(text: &Text) -> String {
    text.0
        .iter()
        .map(|span| match span {
            Span::Plain(s) => s.clone(),
            Span::Code(s) => format!("`{s}`"),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::Column;
    use super::*;

    #[test]
    fn blocks_are_separated_by_a_blank_line_and_tables_align_their_columns() {
        let mut doc = Document::default();
        doc.heading(1, Text::plain("Title ").then_code("x"));
        doc.paragraph("Some words.");
        let mut t = Table::with_columns(vec![Column::left("name"), Column::right("n")]).captioned("Counts:");
        t.push_row(["a", "1"]);
        doc.table(t);
        doc.list(vec![Text::plain("one"), Text::code("two")]);
        assert_eq!(
            doc.to_markdown(),
            "# Title `x`\n\nSome words.\n\nCounts:\n\n| name | n |\n|---|---:|\n| a | 1 |\n\n- one\n- `two`\n"
        );
    }

    #[test]
    fn an_empty_list_leaves_the_blank_line_before_it() {
        let mut doc = Document::default();
        doc.paragraph("p");
        doc.list(Vec::new());
        assert_eq!(doc.to_markdown(), "p\n\n");
        assert_eq!(Document::default().to_markdown(), "");
    }
}
