//! The one Markdown table writer: every report table of the workspace (the size report,
//! the trade-off, the paper reproduction, the flow, the layout) is a [`Table`] — header
//! cells, an alignment per column, rows of strings — rendered with its `|---|` rule.
//!
//! A cell is written `| cell |` (an empty one `|  |`, as the hand-written tables did); a
//! `|` inside a cell is escaped as `\|` so it cannot split the cell. A row with another number of cells than the header
//! is a programming error and panics (in release builds too: the tests run in release),
//! naming both counts; a row that leaves its last columns blank on purpose (a note that
//! runs across them) says so with [`Table::row_spanning`], whose blank cells are written
//! `||`.

use std::fmt;

/// A column's alignment, as its rule cell writes it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Align {
    /// `---`: the renderer's default, left.
    Left,
    /// `---:`: numbers.
    Right,
}

impl Align {
    fn rule(self) -> &'static str {
        match self {
            Align::Left => "---",
            Align::Right => "---:",
        }
    }
}

/// A Markdown table: header cells with their alignment, then rows of the same width.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Table {
    header: Vec<String>,
    align: Vec<Align>,
    /// Each row's cells; fewer than the header's only for a spanning row.
    rows: Vec<Vec<String>>,
}

impl Table {
    /// A table of these columns (header cell, alignment).
    pub fn new<S: Into<String>>(columns: impl IntoIterator<Item = (S, Align)>) -> Self {
        let (header, align) = columns.into_iter().map(|(h, a)| (h.into(), a)).unzip();
        Table {
            header,
            align,
            rows: Vec::new(),
        }
    }

    /// A table whose columns are all left-aligned.
    pub fn left<S: Into<String>>(header: impl IntoIterator<Item = S>) -> Self {
        Table::new(header.into_iter().map(|h| (h, Align::Left)))
    }

    /// A table whose first column is left-aligned and the others right-aligned (a name,
    /// then numbers).
    pub fn numeric<S: Into<String>>(header: impl IntoIterator<Item = S>) -> Self {
        Table::new(
            header
                .into_iter()
                .enumerate()
                .map(|(i, h)| (h, if i == 0 { Align::Left } else { Align::Right })),
        )
    }

    /// Appends a column (header cell, alignment); only before the first row.
    pub fn column(&mut self, header: impl Into<String>, align: Align) -> &mut Self {
        assert!(
            self.rows.is_empty(),
            "markdown table: column added after {} row(s)",
            self.rows.len()
        );
        self.header.push(header.into());
        self.align.push(align);
        self
    }

    /// Appends a row.
    ///
    /// # Panics
    /// When the row has another number of cells than the header (a programming error).
    pub fn row<S: Into<String>>(&mut self, cells: impl IntoIterator<Item = S>) -> &mut Self {
        let cells: Vec<String> = cells.into_iter().map(Into::into).collect();
        assert_eq!(
            cells.len(),
            self.header.len(),
            "markdown table: a row of {} cells under a header of {} ({:?})",
            cells.len(),
            self.header.len(),
            self.header
        );
        self.rows.push(cells);
        self
    }

    /// Appends a row of at most the header's width whose missing last cells are blank,
    /// written `||` (a note in the last given cell runs across them).
    ///
    /// # Panics
    /// When the row has more cells than the header, or none.
    pub fn row_spanning<S: Into<String>>(
        &mut self,
        cells: impl IntoIterator<Item = S>,
    ) -> &mut Self {
        let cells: Vec<String> = cells.into_iter().map(Into::into).collect();
        assert!(
            !cells.is_empty() && cells.len() <= self.header.len(),
            "markdown table: a spanning row of {} cells under a header of {} ({:?})",
            cells.len(),
            self.header.len(),
            self.header
        );
        self.rows.push(cells);
        self
    }

    /// How many rows the table holds (the header and rule not counted).
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// Whether the table holds no row.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// The table: header, rule, rows, each line ending in `\n`.
    pub fn render(&self) -> String {
        self.to_string()
    }
}

/// One line: each cell `| cell |`, then a bare `|` for each of the `blank` columns a
/// spanning row leaves.
fn write_line<'a>(
    f: &mut fmt::Formatter<'_>,
    cells: impl Iterator<Item = &'a str>,
    blank: usize,
) -> fmt::Result {
    f.write_str("|")?;
    for c in cells {
        write!(f, " {} |", c.replace('|', "\\|"))?;
    }
    for _ in 0..blank {
        f.write_str("|")?;
    }
    f.write_str("\n")
}

impl fmt::Display for Table {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write_line(f, self.header.iter().map(String::as_str), 0)?;
        f.write_str("|")?;
        for a in &self.align {
            write!(f, "{}|", a.rule())?;
        }
        f.write_str("\n")?;
        for r in &self.rows {
            write_line(f, r.iter().map(String::as_str), self.header.len() - r.len())?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_rule_and_rows_render_as_written_by_hand() {
        let mut t = Table::new([("block", Align::Left), ("area µm²", Align::Right)]);
        t.row(["adder", "12.5"]).row(["register file", "300"]);
        assert_eq!(
            t.render(),
            "| block | area µm² |\n|---|---:|\n| adder | 12.5 |\n| register file | 300 |\n"
        );
        assert_eq!(t.len(), 2);
        // No rows: the header and the rule alone.
        assert_eq!(Table::left(["a", "b"]).render(), "| a | b |\n|---|---|\n");
    }

    #[test]
    fn alignment_is_per_column() {
        let t = Table::numeric(["name", "x", "y"]);
        assert_eq!(t.render(), "| name | x | y |\n|---|---:|---:|\n");
        let mut t = Table::left(["a"]);
        t.column("b", Align::Right).column("c", Align::Left);
        assert_eq!(t.render(), "| a | b | c |\n|---|---:|---|\n");
    }

    #[test]
    fn a_pipe_in_a_cell_is_escaped_and_an_empty_cell_keeps_its_spaces() {
        let mut t = Table::left(["", "x|y"]);
        t.row(["a|b", ""]);
        assert_eq!(t.render(), "|  | x\\|y |\n|---|---|\n| a\\|b |  |\n");
        // Each line still has exactly columns + 1 unescaped pipes.
        for line in t.render().lines() {
            let unescaped = line.replace("\\|", "").matches('|').count();
            assert_eq!(unescaped, 3, "{line}");
        }
    }

    #[test]
    #[should_panic(expected = "a row of 3 cells under a header of 2")]
    fn a_row_of_the_wrong_width_is_refused() {
        Table::left(["a", "b"]).row(["1", "2", "3"]);
    }

    #[test]
    fn a_spanning_row_leaves_its_last_columns_blank() {
        let mut t = Table::left(["knob", "value", "a", "b", "c"]);
        t.row_spanning(["W", "35", "rejected: too narrow"]);
        assert_eq!(
            t.render(),
            "| knob | value | a | b | c |\n|---|---|---|---|---|\n| W | 35 | rejected: too narrow |||\n"
        );
        // Every line still has as many cells as the header (the rule's count).
        let cells = |l: &str| l.matches('|').count();
        let text = t.render();
        let lines: Vec<&str> = text.lines().collect();
        assert!(
            lines.iter().all(|l| cells(l) == cells(lines[1])),
            "{lines:?}"
        );
    }

    #[test]
    #[should_panic(expected = "a spanning row of 6 cells under a header of 5")]
    fn a_spanning_row_wider_than_the_header_is_refused() {
        Table::left(["a", "b", "c", "d", "e"]).row_spanning(["1"; 6]);
    }

    #[test]
    #[should_panic(expected = "column added after 1 row")]
    fn a_column_after_a_row_is_refused() {
        let mut t = Table::left(["a"]);
        t.row(["1"]);
        t.column("b", Align::Left);
    }
}
