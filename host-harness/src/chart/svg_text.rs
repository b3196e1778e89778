//! The charts' SVG text as glyph outlines: plotters' SVG backend writes
//! each label as a `<text font-family="sans-serif">`, which a viewer draws
//! with whatever font it finds under that name. [`outline_text`] replaces
//! every such element by a `<path>` of the embedded font's glyphs (DejaVu
//! Sans, the font the PNGs are drawn with), laid out as the backend asked:
//! the same position, size, anchor, colour and rotation, so the SVG needs
//! no font at all.
//!
//! Layout (SVG 1.1 §10): the font size `s` maps one em (the font's
//! `units_per_em`) to `s` user units; glyphs advance by their horizontal
//! advance plus the kerning of each pair; `text-anchor` `start`, `middle`,
//! `end` puts the start, middle or end of the advance width at `x`; `dy`
//! moves the baseline by `0.76em` (plotters' top anchor), `0.5ex` (centre)
//! or `-0.5ex` (bottom), the ex being the font's x-height (the top of the
//! `x` glyph).

use core::fmt::Write;

use ab_glyph::{Font, FontRef, OutlineCurve, Point};
use anyhow::{Context, bail};

/// The attributes of one `<text>` element, as plotters writes them.
struct TextElement<'a> {
    x: f64,
    y: f64,
    dy: &'a str,
    anchor: &'a str,
    size: f64,
    fill: &'a str,
    opacity: &'a str,
    transform: Option<&'a str>,
}

/// The value of `name="…"` in the attribute list `attrs`.
fn attribute<'a>(attrs: &'a str, name: &str) -> Option<&'a str> {
    let key = format!(" {name}=\"");
    let start = attrs.find(&key)? + key.len();
    let len = attrs[start..].find('"')?;
    Some(&attrs[start..start + len])
}

impl<'a> TextElement<'a> {
    fn parse(attrs: &'a str) -> anyhow::Result<Self> {
        let get = |name: &str| {
            attribute(attrs, name).with_context(|| format!("<text> without {name}: {attrs}"))
        };
        Ok(Self {
            x: get("x")?.parse()?,
            y: get("y")?.parse()?,
            dy: get("dy")?,
            anchor: get("text-anchor")?,
            size: get("font-size")?.parse()?,
            fill: get("fill")?,
            opacity: attribute(attrs, "opacity").unwrap_or("1"),
            transform: attribute(attrs, "transform"),
        })
    }
}

/// XML text with the five entities plotters escapes unescaped.
fn unescape(text: &str) -> String {
    text.replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&apos;", "'")
        .replace("&amp;", "&")
}

/// `svg` with every `<text …>…</text>` replaced by the outlines of its
/// glyphs in `font` (TrueType/OpenType bytes) as one `<path>`; an error for
/// an unparsable font or element.
pub fn outline_text(svg: &str, font: &[u8]) -> anyhow::Result<String> {
    let font = FontRef::try_from_slice(font).context("the chart font")?;
    let mut out = String::with_capacity(svg.len());
    let mut rest = svg;
    while let Some(start) = rest.find("<text") {
        out.push_str(&rest[..start]);
        let element = &rest[start..];
        let open_end = element.find('>').context("unterminated <text>")?;
        let close = element.find("</text>").context("<text> without </text>")?;
        if close < open_end {
            bail!("malformed <text> element");
        }
        let text = TextElement::parse(&element["<text".len()..open_end])?;
        let content = unescape(element[open_end + 1..close].trim_matches('\n'));
        out.push_str(&path_element(&font, &text, &content));
        rest = &element[close + "</text>".len()..];
        rest = rest.strip_prefix('\n').unwrap_or(rest);
    }
    out.push_str(rest);
    Ok(out)
}

/// The `<path>` of `content` laid out as `text` asks (module documentation).
fn path_element(font: &FontRef<'_>, text: &TextElement<'_>, content: &str) -> String {
    let units = f64::from(font.units_per_em().unwrap_or(2048.0));
    let scale = text.size / units;
    let glyphs: Vec<_> = content.chars().map(|c| font.glyph_id(c)).collect();
    let mut advances = Vec::with_capacity(glyphs.len());
    let mut width = 0.0;
    for (i, &g) in glyphs.iter().enumerate() {
        advances.push(width);
        width += f64::from(font.h_advance_unscaled(g));
        if let Some(&next) = glyphs.get(i + 1) {
            width += f64::from(font.kern_unscaled(g, next));
        }
    }
    let x_height = font
        .outline(font.glyph_id('x'))
        .map_or(0.5 * units, |o| f64::from(o.bounds.max.y));
    let dy = match text.dy {
        "0.76em" => 0.76 * units,
        "0.5ex" => 0.5 * x_height,
        "-0.5ex" => -0.5 * x_height,
        _ => 0.0,
    } * scale;
    let shift = match text.anchor {
        "middle" => 0.5 * width,
        "end" => width,
        _ => 0.0,
    } * scale;
    let (x0, y0) = (text.x - shift, text.y + dy);
    let mut d = String::new();
    for (&g, &advance) in glyphs.iter().zip(&advances) {
        let Some(outline) = font.outline(g) else {
            continue;
        };
        // Font units, y up, to user units, y down.
        let p = |q: Point| {
            (
                x0 + scale * (advance + f64::from(q.x)),
                y0 - scale * f64::from(q.y),
            )
        };
        let mut pen: Option<Point> = None;
        for curve in &outline.curves {
            let (from, to) = match *curve {
                OutlineCurve::Line(a, b) => (a, b),
                OutlineCurve::Quad(a, _, c) => (a, c),
                OutlineCurve::Cubic(a, _, _, d) => (a, d),
            };
            if pen != Some(from) {
                if pen.is_some() {
                    d.push('Z');
                }
                let (x, y) = p(from);
                let _ = write!(d, "M{x:.2} {y:.2}");
            }
            match *curve {
                OutlineCurve::Line(_, b) => {
                    let (x, y) = p(b);
                    let _ = write!(d, "L{x:.2} {y:.2}");
                }
                OutlineCurve::Quad(_, b, c) => {
                    let ((bx, by), (cx, cy)) = (p(b), p(c));
                    let _ = write!(d, "Q{bx:.2} {by:.2} {cx:.2} {cy:.2}");
                }
                OutlineCurve::Cubic(_, b, c, e) => {
                    let ((bx, by), (cx, cy), (ex, ey)) = (p(b), p(c), p(e));
                    let _ = write!(d, "C{bx:.2} {by:.2} {cx:.2} {cy:.2} {ex:.2} {ey:.2}");
                }
            }
            pen = Some(to);
        }
        if pen.is_some() {
            d.push('Z');
        }
    }
    let transform = text
        .transform
        .map_or(String::new(), |t| format!(" transform=\"{t}\""));
    format!(
        "<path d=\"{d}\" fill=\"{}\" opacity=\"{}\"{transform}/>\n",
        text.fill, text.opacity
    )
}
