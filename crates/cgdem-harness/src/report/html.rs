//! A self-contained HTML report page: inline CSS, figures as inline base64
//! PNG, no JavaScript and no external resources, so one file can be mailed or
//! archived and still shows everything. Every piece of text is escaped.

use std::fmt::Write as _;
use std::fs;
use std::io::{self, Write as _};
use std::path::{Component, Path, PathBuf};

use base64::Engine as _;

use super::plot::FigureFiles;

const CSS: &str = "\
body{font-family:'DejaVu Sans',Helvetica,Arial,sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;color:#222;line-height:1.45}
h1{border-bottom:2px solid #0072b2;padding-bottom:.2em}
h2{margin-top:1.8em;border-bottom:1px solid #ccc}
table{border-collapse:collapse;margin:.8em 0}
th,td{border:1px solid #bbb;padding:.25em .6em;text-align:left;vertical-align:top}
th{background:#eef2f6}
table.kv th{background:#f6f6f6;font-weight:600}
td.pass{background:#d9f2d9;color:#145214}
td.fail{background:#f8d4d4;color:#7a0f0f;font-weight:600}
td.skipped{background:#e6e6e6;color:#555}
td.known{background:#fde3a7;color:#6b4400;font-weight:600}
p.banner{font-size:1.25em;font-weight:700;padding:.5em .8em;border-radius:4px}
p.banner.pass{background:#d9f2d9;color:#145214}
p.banner.fail{background:#f8d4d4;color:#7a0f0f}
p.banner.known{background:#fde3a7;color:#6b4400}
p.banner.skipped{background:#e6e6e6;color:#555}
tr:target td{outline:2px solid #0072b2}
td.num{text-align:right;font-variant-numeric:tabular-nums}
figure{margin:1.2em 0}
figure img{max-width:100%;height:auto;border:1px solid #ddd}
figcaption{font-size:.92em;color:#444}
caption{caption-side:top;text-align:left;font-weight:600;padding:.2em 0}
nav ul{columns:2}
code{font-family:'DejaVu Sans Mono',monospace}
";

/// Outcome of a check, shown as the cell's colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    Pass,
    Fail,
    Skipped,
    /// A declared known difference inside its band (amber).
    Known,
}

impl Status {
    fn class(self) -> &'static str {
        match self {
            Self::Pass => "pass",
            Self::Fail => "fail",
            Self::Skipped => "skipped",
            Self::Known => "known",
        }
    }
}

/// One table cell: text, an optional pass/fail/skipped colour, and whether
/// it is a number (right-aligned).
#[derive(Clone, Debug, PartialEq)]
pub struct Cell {
    pub text: String,
    pub status: Option<Status>,
    pub numeric: bool,
    /// A link target (`#row-id` on the same page, or a relative path).
    pub href: Option<String>,
}

impl Cell {
    pub fn text(text: impl Into<String>) -> Self {
        Self {
            text: text.into(),
            status: None,
            numeric: false,
            href: None,
        }
    }

    /// Text that links to `href` (`#id` of a row on the page, or a relative path).
    pub fn link(text: impl Into<String>, href: impl Into<String>) -> Self {
        Self {
            href: Some(href.into()),
            ..Self::text(text)
        }
    }

    /// Right-aligned numeric text; the caller chooses the formatting.
    pub fn num(text: impl Into<String>) -> Self {
        Self {
            numeric: true,
            ..Self::text(text)
        }
    }

    pub fn pass(text: impl Into<String>) -> Self {
        Self::text(text).status(Status::Pass)
    }

    pub fn fail(text: impl Into<String>) -> Self {
        Self::text(text).status(Status::Fail)
    }

    pub fn skipped(text: impl Into<String>) -> Self {
        Self::text(text).status(Status::Skipped)
    }

    pub fn status(mut self, status: Status) -> Self {
        self.status = Some(status);
        self
    }
}

impl From<&str> for Cell {
    fn from(s: &str) -> Self {
        Self::text(s)
    }
}

impl From<String> for Cell {
    fn from(s: String) -> Self {
        Self::text(s)
    }
}

/// A data table with a header row.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Table {
    pub caption: Option<String>,
    pub header: Vec<String>,
    pub rows: Vec<Vec<Cell>>,
    /// Anchors of rows (`id` attribute), by row index, for links from elsewhere on the page.
    pub row_ids: Vec<(usize, String)>,
}

impl Table {
    pub fn new<S: Into<String>>(header: impl IntoIterator<Item = S>) -> Self {
        Self {
            caption: None,
            header: header.into_iter().map(Into::into).collect(),
            rows: Vec::new(),
            row_ids: Vec::new(),
        }
    }

    pub fn caption(mut self, caption: impl Into<String>) -> Self {
        self.caption = Some(caption.into());
        self
    }

    pub fn row<C: Into<Cell>>(&mut self, cells: impl IntoIterator<Item = C>) -> &mut Self {
        self.rows.push(cells.into_iter().map(Into::into).collect());
        self
    }

    /// A row that links can reach as `#id`.
    pub fn row_with_id<C: Into<Cell>>(
        &mut self,
        id: impl Into<String>,
        cells: impl IntoIterator<Item = C>,
    ) -> &mut Self {
        self.row_ids.push((self.rows.len(), id.into()));
        self.row(cells)
    }
}

#[derive(Clone, Debug, PartialEq)]
struct EmbeddedFigure {
    png_base64: String,
    png: PathBuf,
    svg: PathBuf,
    csv: PathBuf,
    alt: String,
    caption: String,
}

#[derive(Clone, Debug, PartialEq)]
enum Block {
    Paragraph(String),
    /// A coloured one-line status, e.g. the night's verdict.
    Banner(Status, String),
    /// A bulleted list of cells (text or links).
    List(Vec<Cell>),
    KeyValues(Option<String>, Vec<(String, String)>),
    Table(Table),
    Figure(EmbeddedFigure),
    Section(Section),
}

/// A headed part of the report; sections nest (h2, h3, ... up to h6).
#[derive(Clone, Debug, PartialEq)]
pub struct Section {
    heading: String,
    blocks: Vec<Block>,
}

impl Section {
    fn new(heading: impl Into<String>) -> Self {
        Self {
            heading: heading.into(),
            blocks: Vec::new(),
        }
    }

    pub fn paragraph(&mut self, text: impl Into<String>) -> &mut Self {
        self.blocks.push(Block::Paragraph(text.into()));
        self
    }

    /// A coloured status line (green pass, amber known, red fail, grey skipped).
    pub fn banner(&mut self, status: Status, text: impl Into<String>) -> &mut Self {
        self.blocks.push(Block::Banner(status, text.into()));
        self
    }

    /// A bulleted list; items may be links (`Cell::link`).
    pub fn list(&mut self, items: Vec<Cell>) -> &mut Self {
        self.blocks.push(Block::List(items));
        self
    }

    /// A two-column key/value table, e.g. provenance: code versions, git
    /// commit, host, command line, date.
    pub fn key_values<K: Into<String>, V: Into<String>>(
        &mut self,
        caption: Option<&str>,
        rows: impl IntoIterator<Item = (K, V)>,
    ) -> &mut Self {
        let rows = rows
            .into_iter()
            .map(|(k, v)| (k.into(), v.into()))
            .collect();
        self.blocks
            .push(Block::KeyValues(caption.map(str::to_string), rows));
        self
    }

    pub fn table(&mut self, table: Table) -> &mut Self {
        self.blocks.push(Block::Table(table));
        self
    }

    /// Embeds `files.png` inline; the caption links to the CSV and SVG by
    /// path relative to the page, and mentions points left out of the plot.
    pub fn figure(
        &mut self,
        files: &FigureFiles,
        alt: impl Into<String>,
        caption: impl Into<String>,
    ) -> io::Result<&mut Self> {
        let bytes = fs::read(&files.png)
            .map_err(|e| io::Error::new(e.kind(), format!("{}: {e}", files.png.display())))?;
        let mut caption = caption.into();
        if let Some(note) = files.note() {
            if !caption.is_empty() {
                caption.push(' ');
            }
            caption.push_str(&note);
        }
        self.blocks.push(Block::Figure(EmbeddedFigure {
            png_base64: base64::engine::general_purpose::STANDARD.encode(bytes),
            png: files.png.clone(),
            svg: files.svg.clone(),
            csv: files.csv.clone(),
            alt: alt.into(),
            caption,
        }));
        Ok(self)
    }

    pub fn subsection(&mut self, heading: impl Into<String>) -> &mut Section {
        self.blocks.push(Block::Section(Section::new(heading)));
        match self.blocks.last_mut() {
            Some(Block::Section(s)) => s,
            _ => unreachable!("just pushed a section"),
        }
    }
}

/// A report page. Build it with [`Report::section`], then [`Report::write`].
#[derive(Clone, Debug, PartialEq)]
pub struct Report {
    title: String,
    intro: Section,
    sections: Vec<Section>,
}

impl Report {
    pub fn new(title: impl Into<String>) -> Self {
        Self {
            title: title.into(),
            intro: Section::new(""),
            sections: Vec::new(),
        }
    }

    /// Content above the first section (summary, provenance).
    pub fn intro(&mut self) -> &mut Section {
        &mut self.intro
    }

    pub fn section(&mut self, heading: impl Into<String>) -> &mut Section {
        self.sections.push(Section::new(heading));
        self.sections.last_mut().expect("just pushed")
    }

    /// The section written last, to add to (none before the first).
    pub fn last_section(&mut self) -> Option<&mut Section> {
        self.sections.last_mut()
    }

    /// The page as a string; links to CSV/SVG files are made relative to
    /// `page_dir`, the directory the page will be written to.
    pub fn render(&self, page_dir: &Path) -> String {
        let mut out = String::with_capacity(64 * 1024);
        let _ = write!(
            out,
            "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
             <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
             <title>{}</title>\n<style>\n{CSS}</style>\n</head>\n<body>\n<h1>{}</h1>\n",
            escape(&self.title),
            escape(&self.title)
        );
        let mut r = Renderer {
            out,
            page_dir,
            next_id: 0,
        };
        r.blocks(&self.intro.blocks, 2);
        if self.sections.len() > 1 {
            r.out.push_str("<nav>\n<ul>\n");
            for (i, s) in self.sections.iter().enumerate() {
                let _ = writeln!(
                    r.out,
                    "<li><a href=\"#s{}\">{}</a></li>",
                    i + 1,
                    escape(&s.heading)
                );
            }
            r.out.push_str("</ul>\n</nav>\n");
        }
        for (i, s) in self.sections.iter().enumerate() {
            let _ = writeln!(
                r.out,
                "<section id=\"s{}\">\n<h2>{}</h2>",
                i + 1,
                escape(&s.heading)
            );
            r.blocks(&s.blocks, 3);
            r.out.push_str("</section>\n");
        }
        r.out.push_str("</body>\n</html>\n");
        r.out
    }

    /// Writes the page atomically: a temporary file in the same directory,
    /// synced, then renamed over `path`, so a reader never sees half a page.
    pub fn write(&self, path: &Path) -> io::Result<()> {
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        fs::create_dir_all(&dir)?;
        let html = self.render(&dir);
        let name = path.file_name().ok_or_else(|| {
            io::Error::new(io::ErrorKind::InvalidInput, "report path has no file name")
        })?;
        let tmp = dir.join(format!(
            ".{}.tmp{}",
            name.to_string_lossy(),
            std::process::id()
        ));
        let result = (|| {
            let mut f = fs::File::create(&tmp)?;
            f.write_all(html.as_bytes())?;
            f.sync_all()?;
            fs::rename(&tmp, path)
        })();
        if result.is_err() {
            let _ = fs::remove_file(&tmp);
        }
        result
    }
}

struct Renderer<'a> {
    out: String,
    page_dir: &'a Path,
    next_id: usize,
}

impl Renderer<'_> {
    fn blocks(&mut self, blocks: &[Block], level: usize) {
        for b in blocks {
            match b {
                Block::Paragraph(t) => {
                    let _ = writeln!(self.out, "<p>{}</p>", escape(t));
                }
                Block::Banner(status, t) => {
                    let _ = writeln!(
                        self.out,
                        "<p class=\"banner {}\">{}</p>",
                        status.class(),
                        escape(t)
                    );
                }
                Block::List(items) => {
                    self.out.push_str("<ul>\n");
                    for c in items {
                        let _ = writeln!(self.out, "<li>{}</li>", cell_content(c));
                    }
                    self.out.push_str("</ul>\n");
                }
                Block::KeyValues(caption, rows) => {
                    self.out.push_str("<table class=\"kv\">\n");
                    if let Some(c) = caption {
                        let _ = writeln!(self.out, "<caption>{}</caption>", escape(c));
                    }
                    for (k, v) in rows {
                        let _ = writeln!(
                            self.out,
                            "<tr><th scope=\"row\">{}</th><td>{}</td></tr>",
                            escape(k),
                            escape(v)
                        );
                    }
                    self.out.push_str("</table>\n");
                }
                Block::Table(t) => self.table(t),
                Block::Figure(f) => self.figure(f),
                Block::Section(s) => {
                    let h = level.min(6);
                    let _ = writeln!(self.out, "<section>\n<h{h}>{}</h{h}>", escape(&s.heading));
                    self.blocks(&s.blocks, level + 1);
                    self.out.push_str("</section>\n");
                }
            }
        }
    }

    fn table(&mut self, t: &Table) {
        self.out.push_str("<table>\n");
        if let Some(c) = &t.caption {
            let _ = writeln!(self.out, "<caption>{}</caption>", escape(c));
        }
        if !t.header.is_empty() {
            self.out.push_str("<thead><tr>");
            for h in &t.header {
                let _ = write!(self.out, "<th scope=\"col\">{}</th>", escape(h));
            }
            self.out.push_str("</tr></thead>\n");
        }
        self.out.push_str("<tbody>\n");
        for (k, row) in t.rows.iter().enumerate() {
            match t.row_ids.iter().find(|(i, _)| *i == k) {
                Some((_, id)) => {
                    let _ = write!(self.out, "<tr id=\"{}\">", escape(id));
                }
                None => self.out.push_str("<tr>"),
            }
            for c in row {
                let mut classes = Vec::new();
                if let Some(s) = c.status {
                    classes.push(s.class());
                }
                if c.numeric {
                    classes.push("num");
                }
                if classes.is_empty() {
                    let _ = write!(self.out, "<td>{}</td>", cell_content(c));
                } else {
                    let _ = write!(
                        self.out,
                        "<td class=\"{}\">{}</td>",
                        classes.join(" "),
                        cell_content(c)
                    );
                }
            }
            self.out.push_str("</tr>\n");
        }
        self.out.push_str("</tbody>\n</table>\n");
    }

    fn figure(&mut self, f: &EmbeddedFigure) {
        self.next_id += 1;
        let link = |p: &Path| escape(&url_path(&relative_to(p, self.page_dir)));
        let (csv, svg, png) = (link(&f.csv), link(&f.svg), link(&f.png));
        let _ = writeln!(
            self.out,
            "<figure id=\"fig{id}\">\n<img src=\"data:image/png;base64,{b64}\" alt=\"{alt}\">\n\
             <figcaption><strong>Figure {id}.</strong> {cap} \
             Data: <a href=\"{csv}\">{csv}</a>; vector: <a href=\"{svg}\">{svg}</a>; \
             raster: <a href=\"{png}\">{png}</a>.</figcaption>\n</figure>",
            id = self.next_id,
            b64 = f.png_base64,
            alt = escape(&f.alt),
            cap = escape(&f.caption),
        );
    }
}

/// A cell's text, escaped, inside a link when it has one.
fn cell_content(c: &Cell) -> String {
    match &c.href {
        Some(href) => format!("<a href=\"{}\">{}</a>", escape(href), escape(&c.text)),
        None => escape(&c.text),
    }
}

/// Escapes text for HTML element content and quoted attribute values.
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            _ => out.push(c),
        }
    }
    out
}

/// `path` relative to `base` (both made absolute against the current
/// directory first); falls back to the absolute path across drives/roots.
fn relative_to(path: &Path, base: &Path) -> PathBuf {
    let abs = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    let (path, base) = (abs(path), abs(base));
    let (p, b) = (normalized(&path), normalized(&base));
    if p.first() != b.first() {
        return path;
    }
    let common = p.iter().zip(&b).take_while(|(x, y)| x == y).count();
    let mut rel = PathBuf::new();
    for _ in common..b.len() {
        rel.push("..");
    }
    for c in &p[common..] {
        rel.push(c.as_os_str());
    }
    rel
}

/// Components with `.` dropped and `x/..` folded (lexically, no symlinks).
fn normalized(p: &Path) -> Vec<Component<'_>> {
    let mut v: Vec<Component> = Vec::new();
    for c in p.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir if matches!(v.last(), Some(Component::Normal(_))) => {
                v.pop();
            }
            _ => v.push(c),
        }
    }
    v
}

/// A relative file path as a URL path: forward slashes, and percent-encoding
/// for the characters that would break or change a URL.
fn url_path(p: &Path) -> String {
    let s = p.to_string_lossy().replace('\\', "/");
    let mut out = String::with_capacity(s.len());
    for b in s.bytes() {
        match b {
            b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'-' | b'_' | b'.' | b'~' | b'/' => {
                out.push(b as char)
            }
            _ => {
                let _ = write!(out, "%{b:02X}");
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::plot::{write_figure, Figure, Series};

    /// Checks that every tag this module emits is closed in order; void
    /// elements (`meta`, `img`) and the doctype are exempt.
    fn assert_balanced(html: &str) {
        let mut stack: Vec<String> = Vec::new();
        let mut rest = html;
        while let Some(i) = rest.find('<') {
            rest = &rest[i + 1..];
            let end = rest.find('>').expect("unterminated tag");
            let tag = &rest[..end];
            rest = &rest[end + 1..];
            if tag.starts_with('!') {
                continue;
            }
            let name: String = tag
                .trim_start_matches('/')
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric())
                .collect();
            assert!(!name.is_empty(), "bad tag <{tag}>");
            if matches!(name.as_str(), "meta" | "img" | "br") {
                continue;
            }
            if tag.starts_with('/') {
                assert_eq!(stack.pop().as_deref(), Some(name.as_str()), "at </{name}>");
            } else {
                stack.push(name);
            }
        }
        assert!(stack.is_empty(), "unclosed: {stack:?}");
    }

    #[test]
    fn text_is_escaped_everywhere() {
        assert_eq!(
            escape(r#"<b>"Tom" & 'Jerry'</b>"#),
            "&lt;b&gt;&quot;Tom&quot; &amp; &#39;Jerry&#39;&lt;/b&gt;"
        );
        let mut r = Report::new("E < 1 & v > 0");
        r.intro()
            .key_values(Some("<caption>"), [("git <sha>", "a&b")]);
        let s = r.section("<script>alert(1)</script>");
        s.paragraph("x < y");
        let mut t = Table::new(["<th>"]);
        t.row([Cell::fail("\"quoted\"")]);
        s.table(t);
        let html = r.render(Path::new("."));
        assert!(!html.contains("<script>"));
        assert!(html.contains("<title>E &lt; 1 &amp; v &gt; 0</title>"));
        assert!(html.contains("&lt;script&gt;alert(1)&lt;/script&gt;"));
        assert!(html.contains("<td class=\"fail\">&quot;quoted&quot;</td>"));
        assert!(html.contains("<th scope=\"row\">git &lt;sha&gt;</th><td>a&amp;b</td>"));
        assert_balanced(&html);
    }

    #[test]
    fn report_embeds_every_figure_and_is_well_formed() {
        let dir = crate::report::plot::tests::test_dir("html");
        let figs_dir = dir.join("figures");
        let a = write_figure(
            &figs_dir,
            "restitution",
            &crate::report::plot::tests::restitution_figure(),
        )
        .unwrap();
        let b = write_figure(
            &figs_dir,
            "energy",
            &Figure::new("Energy drift", "time t [s]", "relative drift |dE/E0| [-]")
                .log_y()
                .with_series(Series::new(
                    "cgdem",
                    vec![(0.0, 1e-9), (1.0, f64::NAN), (2.0, 3e-8)],
                )),
        )
        .unwrap();

        let mut r = Report::new("cgdem validation: smoke");
        r.intro().key_values(
            Some("Provenance"),
            [
                ("cgdem", "0.1.0 (abc1234)"),
                ("host", "ci"),
                ("date", "2025-01-01"),
            ],
        );
        let s = r.section("Restitution");
        s.paragraph("Hertz normal force with viscous damping.");
        let mut t = Table::new(["case", "e (cgdem)", "e (LIGGGHTS)", "status"]);
        t.row([
            Cell::text("v = 1 m/s"),
            Cell::num("0.9"),
            Cell::num("0.9"),
            Cell::pass("pass"),
        ]);
        t.row([
            Cell::text("v = 9 m/s"),
            Cell::num("0.7"),
            Cell::num("0.8"),
            Cell::fail("fail"),
        ]);
        t.row([
            Cell::text("v = 90 m/s"),
            Cell::num("-"),
            Cell::num("-"),
            Cell::skipped("skipped"),
        ]);
        s.table(t.caption("Restitution by impact speed"));
        s.figure(
            &a,
            "restitution vs velocity",
            "Restitution against impact velocity.",
        )
        .unwrap();
        s.subsection("Energy")
            .figure(&b, "energy drift", "")
            .unwrap();
        r.section("Throughput").paragraph("none yet");

        let page = dir.join("report.html");
        r.write(&page).unwrap();
        let html = fs::read_to_string(&page).unwrap();
        for f in [&a, &b] {
            let b64 = base64::engine::general_purpose::STANDARD.encode(fs::read(&f.png).unwrap());
            assert!(html.contains(&format!("src=\"data:image/png;base64,{b64}\"")));
            let stem = f.png.file_stem().unwrap().to_string_lossy();
            assert!(html.contains(&format!("href=\"figures/{stem}.csv\"")));
            assert!(html.contains(&format!("href=\"figures/{stem}.svg\"")));
        }
        assert!(html.contains("1 point with NaN/inf values not shown"));
        assert!(html.contains("<td class=\"skipped\">skipped</td>"));
        assert!(html.contains("<td class=\"pass\">pass</td>"));
        assert!(
            !html.contains("<script") && !html.contains("http://") && !html.contains("https://")
        );
        assert_balanced(&html);
        // No temporary file left behind.
        let leftovers: Vec<_> = fs::read_dir(&dir)
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().contains(".tmp"))
            .collect();
        assert!(leftovers.is_empty());
    }

    #[test]
    fn relative_links() {
        assert_eq!(
            relative_to(Path::new("/r/out/figs/a.csv"), Path::new("/r/out")),
            PathBuf::from("figs/a.csv")
        );
        assert_eq!(
            relative_to(Path::new("/r/data/a.csv"), Path::new("/r/out/")),
            PathBuf::from("../data/a.csv")
        );
        assert_eq!(url_path(Path::new("a b/c#1.csv")), "a%20b/c%231.csv");
    }

    #[test]
    fn status_lines_links_and_row_anchors_render_escaped_and_balanced() {
        let mut report = Report::new("t");
        let intro = report.intro();
        intro.banner(Status::Known, "Status: amber <1 known>");
        intro.list(vec![
            Cell::link("row \"1\"", "#comparison-1"),
            Cell::text("a & b"),
        ]);
        let mut table = Table::new(["verdict"]);
        table.row_with_id("comparison-1", [Cell::text("x").status(Status::Known)]);
        table.row([Cell::fail("fail")]);
        intro.table(table);
        let html = report.render(Path::new("."));
        assert_balanced(&html);
        assert!(html.contains("<p class=\"banner known\">Status: amber &lt;1 known&gt;</p>"));
        assert!(html.contains("<li><a href=\"#comparison-1\">row &quot;1&quot;</a></li>"));
        assert!(html.contains("<tr id=\"comparison-1\"><td class=\"known\">x</td></tr>"));
        assert!(html.contains("<tr><td class=\"fail\">fail</td></tr>"));
        assert!(html.contains("td.known{"), "amber has its own colour");
    }
}
