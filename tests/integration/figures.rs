//! Every kind of figure termid draws, rendered through the CLI and checked as a person looks
//! at it, read off the SVG itself: tracks at equal scale with a tick per ship length, axes
//! labelled with units, every legend inside its panel and over none of the data, no text
//! over another.

use super::common::{termid, Scratch};
use std::path::{Path, PathBuf};

/// One SVG element: its name, attributes, and text (for `<text>`).
struct Element {
    name: String,
    attrs: Vec<(String, String)>,
    text: String,
}

impl Element {
    fn get(&self, key: &str) -> Option<&str> {
        self.attrs.iter().find(|(k, _)| k == key).map(|(_, v)| v.as_str())
    }
    fn num(&self, key: &str) -> f64 {
        self.get(key).and_then(|v| v.parse().ok()).unwrap_or(f64::NAN)
    }
    fn points(&self) -> Vec<(f64, f64)> {
        self.get("points")
            .unwrap_or("")
            .split_whitespace()
            .filter_map(|p| {
                let (x, y) = p.split_once(',')?;
                Some((x.parse().ok()?, y.parse().ok()?))
            })
            .collect()
    }
}

/// The elements of an SVG in document order (plotters writes one tag a line, no nesting
/// beyond `<text>…</text>`).
fn elements(svg: &str) -> Vec<Element> {
    let mut out = Vec::new();
    let mut rest = svg;
    while let Some(start) = rest.find('<') {
        rest = &rest[start + 1..];
        let Some(end) = rest.find('>') else { break };
        let tag = &rest[..end];
        rest = &rest[end + 1..];
        if tag.starts_with('/') || tag.starts_with('?') || tag.starts_with('!') {
            continue;
        }
        let name: String = tag.chars().take_while(|c| c.is_alphanumeric()).collect();
        let mut attrs = Vec::new();
        let mut a = &tag[name.len()..];
        while let Some(eq) = a.find("=\"") {
            let key = a[..eq].trim().to_string();
            let after = &a[eq + 2..];
            let Some(close) = after.find('"') else { break };
            attrs.push((key, after[..close].to_string()));
            a = &after[close + 1..];
        }
        let mut text = String::new();
        if name == "text" {
            if let Some(close) = rest.find("</text>") {
                text = rest[..close].trim().to_string();
                rest = &rest[close..];
            }
        }
        out.push(Element { name, attrs, text });
    }
    out
}

#[derive(Clone, Copy, Debug)]
struct Box2 {
    x0: f64,
    y0: f64,
    x1: f64,
    y1: f64,
}

impl Box2 {
    fn overlaps(&self, o: &Box2) -> bool {
        self.x0 < o.x1 && o.x0 < self.x1 && self.y0 < o.y1 && o.y0 < self.y1
    }
    fn contains(&self, (x, y): (f64, f64)) -> bool {
        x > self.x0 && x < self.x1 && y > self.y0 && y < self.y1
    }
    fn within(&self, o: &Box2, slack: f64) -> bool {
        self.x0 >= o.x0 - slack
            && self.x1 <= o.x1 + slack
            && self.y0 >= o.y0 - slack
            && self.y1 <= o.y1 + slack
    }
    fn shrunk(&self, by: f64) -> Box2 {
        Box2 { x0: self.x0 + by, y0: self.y0 + by, x1: self.x1 - by, y1: self.y1 - by }
    }
}

/// The box a text takes: 0.55 em a character, 1 em high, placed by its anchor, its `dy`
/// (0.76em: y is the top; ±0.5ex: y is about the middle or the bottom) and a rotation by 270°
/// about its anchor point (a y-axis description).
fn text_box(e: &Element) -> Box2 {
    let size = e.num("font-size");
    let chars = e.text.chars().count() as f64;
    let (x, y) = (e.num("x"), e.num("y"));
    let w = 0.55 * size * chars;
    let along = match e.get("text-anchor") {
        Some("middle") => -w / 2.0,
        Some("end") => -w,
        _ => 0.0,
    };
    let top = match e.get("dy") {
        Some("0.76em") => 0.0,
        Some("0.5ex") => -0.5 * size,
        Some("-0.5ex") => -size,
        _ => -0.8 * size,
    };
    if e.get("transform").is_some_and(|t| t.starts_with("rotate(270")) {
        // the text runs upwards from its anchor; its top faces left
        Box2 { x0: x + top, y0: y - along - w, x1: x + top + size, y1: y - along }
    } else {
        Box2 { x0: x + along, y0: y + top, x1: x + along + w, y1: y + top + size }
    }
}

/// The plotting areas: the extent of the mesh lines (faint lines across the area), grouped
/// into rectangles of vertical lines' height and horizontal lines' width.
fn plot_areas(els: &[Element]) -> Vec<Box2> {
    let mesh: Vec<&Element> = els.iter().filter(|e| e.name == "line").collect();
    let mut vertical: Vec<(f64, f64, f64)> = Vec::new(); // x, top, bottom
    let mut horizontal: Vec<(f64, f64, f64)> = Vec::new(); // y, left, right
    for l in mesh {
        let (x1, y1, x2, y2) = (l.num("x1"), l.num("y1"), l.num("x2"), l.num("y2"));
        if x1 == x2 {
            vertical.push((x1, y1.min(y2), y1.max(y2)));
        } else if y1 == y2 {
            horizontal.push((y1, x1.min(x2), x1.max(x2)));
        }
    }
    let mut areas: Vec<Box2> = Vec::new();
    for &(x, top, bottom) in &vertical {
        for &(y, left, right) in &horizontal {
            if x >= left && x <= right && y >= top && y <= bottom {
                let b = Box2 { x0: left, y0: top, x1: right, y1: bottom };
                if !areas.iter().any(|a| (a.x0, a.y0, a.x1, a.y1) == (b.x0, b.y0, b.x1, b.y1)) {
                    areas.push(b);
                }
            }
        }
    }
    areas
}

/// Whether a polyline from `a` to `b` passes through the box (checked every pixel).
fn crosses(a: (f64, f64), b: (f64, f64), r: &Box2) -> bool {
    let n = ((b.0 - a.0).hypot(b.1 - a.1)).ceil().max(1.0) as usize;
    (0..=n).any(|i| {
        let f = i as f64 / n as f64;
        r.contains((a.0 + f * (b.0 - a.0), a.1 + f * (b.1 - a.1)))
    })
}

/// Everything a person would object to in one figure, as sentences (empty: none).
fn objections(file: &Path) -> Vec<String> {
    let svg = std::fs::read_to_string(file).unwrap();
    let els = elements(&svg);
    let name = file.file_name().unwrap().to_string_lossy().to_string();
    let mut found = Vec::new();
    let areas = plot_areas(&els);
    assert!(!areas.is_empty(), "{name}: no plotting area found");
    let texts: Vec<(usize, &Element, Box2)> = els
        .iter()
        .enumerate()
        .filter(|(_, e)| e.name == "text" && !e.text.is_empty())
        .map(|(k, e)| (k, e, text_box(e)))
        .collect();

    // legends: the white box, inside a plotting area, over none of what was drawn before it
    // (the lines, markers and bands of its panel)
    let legends: Vec<(usize, Box2)> = els
        .iter()
        .enumerate()
        .filter(|(_, e)| {
            e.name == "rect" && e.get("fill") == Some("#FFFFFF") && e.get("opacity") == Some("0.85")
        })
        .map(|(k, e)| {
            (
                k,
                Box2 {
                    x0: e.num("x"),
                    y0: e.num("y"),
                    x1: e.num("x") + e.num("width"),
                    y1: e.num("y") + e.num("height"),
                },
            )
        })
        .collect();
    for (k, legend) in &legends {
        if !areas.iter().any(|a| legend.within(a, 1.0)) {
            found.push(format!("{name}: a legend at {legend:?} is not inside its panel's plotting area"));
        }
        let inner = legend.shrunk(1.0);
        let covered = els[..*k].iter().any(|e| match e.name.as_str() {
            "polyline" | "polygon" => e.points().windows(2).any(|p| crosses(p[0], p[1], &inner)),
            "circle" => inner.contains((e.num("cx"), e.num("cy"))),
            _ => false,
        });
        if covered {
            let entries: Vec<&str> = texts
                .iter()
                .filter(|(_, _, b)| b.within(legend, 1.0))
                .map(|(_, e, _)| e.text.as_str())
                .collect();
            found.push(format!("{name}: the legend {entries:?} covers data"));
        }
    }

    // no text over another (a legend's entries are inside its box, nothing else is)
    for (i, (_, a, ba)) in texts.iter().enumerate() {
        for (_, b, bb) in &texts[i + 1..] {
            if ba.shrunk(0.5).overlaps(&bb.shrunk(0.5)) {
                found.push(format!("{name}: `{}` and `{}` overlap", a.text, b.text));
            }
        }
        for (_, legend) in &legends {
            if ba.overlaps(legend) && !ba.within(legend, 1.0) {
                found.push(format!("{name}: `{}` runs under a legend", a.text));
            }
        }
    }

    // axis descriptions: y (rotated) and x (below the ticks) name a unit, except counted axes
    let counted = ["step", "data alternative (1 exact … 5 rounded, differentiated)"];
    for (_, e, _) in &texts {
        let is_axis = e.get("transform").is_some() || e.get("dy") == Some("-0.5ex");
        let unit = e.text.find('[').zip(e.text.find(']')).is_some_and(|(a, b)| b > a + 1);
        if is_axis && !unit && !counted.contains(&e.text.as_str()) {
            found.push(format!("{name}: the axis `{}` has no unit", e.text));
        }
    }

    // one time axis: every panel over time shows the same span, read off its tick labels
    let spans: Vec<(f64, f64)> = texts
        .iter()
        .filter(|(_, e, _)| e.get("dy") == Some("-0.5ex") && e.text == "t [s]")
        .filter_map(|(_, desc, _)| x_span(&texts, &areas, desc))
        .collect();
    if let Some(first) = spans.first() {
        let width = (first.1 - first.0).abs().max(1e-9);
        for span in &spans[1..] {
            if (span.0 - first.0).abs() > 0.01 * width || (span.1 - first.1).abs() > 0.01 * width {
                found.push(format!(
                    "{name}: panels over time span {:.1}-{:.1} s and {:.1}-{:.1} s",
                    first.0, first.1, span.0, span.1
                ));
            }
        }
    }

    // a series keeps its colour and style: each legend entry's picture (colour, line, dashes,
    // marker, ring, band) is the same wherever its name appears in the figure
    let top = areas.iter().map(|a| a.y0).fold(f64::INFINITY, f64::min);
    let mut pictures: Vec<(String, String)> = Vec::new();
    for (_, e, b) in &texts {
        let in_box = legends.iter().any(|(_, l)| b.within(l, 1.0));
        let in_row = b.y1 < top && e.num("font-size") < 10.0;
        if !(in_box || in_row) {
            continue;
        }
        let picture = glyph(&els, b);
        match pictures.iter().find(|(n, _)| *n == e.text) {
            Some((_, seen)) if *seen != picture => {
                found.push(format!("{name}: `{}` is drawn as {seen} and as {picture}", e.text))
            }
            Some(_) => {}
            None => pictures.push((e.text.clone(), picture)),
        }
    }

    // tracks: the same pixels per unit on both axes, read off the tick labels, and a tick at
    // every whole ship length
    for (_, desc, _) in
        texts.iter().filter(|(_, e, _)| e.get("dy") == Some("-0.5ex") && e.text.contains("/L"))
    {
        let area = area_of(&areas, desc).expect("the track's plotting area");
        let ticks = |horizontal: bool| -> Vec<(f64, f64)> {
            texts
                .iter()
                .filter(|(_, e, _)| {
                    if horizontal {
                        e.get("dy") == Some("0.76em") && e.num("y") > area.y1 && e.num("y") < area.y1 + 20.0
                    } else {
                        e.get("text-anchor") == Some("end")
                            && e.num("x") < area.x0
                            && e.num("x") > area.x0 - 20.0
                    }
                })
                .filter(|(_, e, _)| {
                    let at = if horizontal { e.num("x") } else { e.num("y") };
                    let (lo, hi) = if horizontal { (area.x0, area.x1) } else { (area.y0, area.y1) };
                    at >= lo - 1.0 && at <= hi + 1.0
                })
                .filter_map(|(_, e, _)| {
                    let v: f64 = e.text.replace('−', "-").parse().ok()?;
                    Some((v, if horizontal { e.num("x") } else { e.num("y") }))
                })
                .collect()
        };
        let scale = |t: &[(f64, f64)]| {
            let (a, b) = (t.first().unwrap(), t.last().unwrap());
            ((b.1 - a.1) / (b.0 - a.0)).abs()
        };
        let (tx, ty) = (ticks(true), ticks(false));
        assert!(tx.len() >= 3 && ty.len() >= 3, "{name}: track ticks {tx:?} {ty:?}");
        let (sx, sy) = (scale(&tx), scale(&ty));
        if (sx / sy - 1.0).abs() > 0.02 {
            found.push(format!(
                "{name}: the track is drawn at {sx:.1} px per L across and {sy:.1} px per L up"
            ));
        }
        for (v, _) in tx.iter().chain(&ty) {
            if v.fract() != 0.0 {
                found.push(format!("{name}: the track's tick {v} is not a whole ship length"));
            }
        }
        // a tick per length where they stand 40 px apart or more
        let step = (tx[1].0 - tx[0].0).abs();
        if step != 1.0 && sx >= 40.0 {
            found.push(format!(
                "{name}: a track tick every {step} L where one per length fits ({sx:.0} px per L)"
            ));
        }
    }
    found
}

/// The plotting area above an x-axis description: the nearest one whose width holds it.
fn area_of<'a>(areas: &'a [Box2], desc: &Element) -> Option<&'a Box2> {
    let y = desc.num("y");
    areas
        .iter()
        .filter(|a| a.y1 < y && desc.num("x") > a.x0 && desc.num("x") < a.x1)
        .min_by(|a, b| (y - a.y1).total_cmp(&(y - b.y1)))
}

/// The x values at the left and right edge of the plotting area above `desc`, from the tick
/// labels under it (a straight line through them).
fn x_span(texts: &[(usize, &Element, Box2)], areas: &[Box2], desc: &Element) -> Option<(f64, f64)> {
    let area = area_of(areas, desc)?;
    let ticks: Vec<(f64, f64)> = texts
        .iter()
        .filter(|(_, e, _)| {
            e.get("dy") == Some("0.76em") && e.num("y") > area.y1 && e.num("y") < area.y1 + 20.0
        })
        .filter(|(_, e, _)| e.num("x") >= area.x0 - 1.0 && e.num("x") <= area.x1 + 1.0)
        .filter_map(|(_, e, _)| Some((e.num("x"), e.text.replace('−', "-").parse::<f64>().ok()?)))
        .collect();
    let (a, b) = (ticks.first()?, ticks.last()?);
    if ticks.len() < 2 || b.0 == a.0 {
        return None;
    }
    let per_px = (b.1 - a.1) / (b.0 - a.0);
    Some((a.1 + (area.x0 - a.0) * per_px, a.1 + (area.x1 - a.0) * per_px))
}

/// A legend entry's picture: the colours and shapes drawn left of its text, on its line
/// (`line #000000`, `dashes #D62728`, `marker`, `ring`, `band`).
fn glyph(els: &[Element], text: &Box2) -> String {
    let (mid, left) = ((text.y0 + text.y1) / 2.0, text.x0);
    let near = |x: f64, y: f64| x > left - 34.0 && x < left && (y - mid).abs() < 6.0;
    let mut parts: Vec<String> = Vec::new();
    let mut segments = 0;
    let mut colour = String::new();
    for e in els {
        match e.name.as_str() {
            "polyline" => {
                let p = e.points();
                if p.len() == 2 && p.iter().all(|(x, y)| near(*x, *y)) {
                    segments += 1;
                    colour = e.get("stroke").unwrap_or("").to_string();
                }
            }
            "circle" if near(e.num("cx"), e.num("cy")) => {
                let kind = if e.get("fill") == Some("none") { "ring" } else { "marker" };
                parts.push(format!(
                    "{kind} {}",
                    e.get("stroke").filter(|c| *c != "none").or(e.get("fill")).unwrap_or("")
                ));
            }
            "rect" if e.get("width") == Some("18") && near(e.num("x") + 9.0, e.num("y") + 5.0) => {
                parts.push(format!("band {}", e.get("fill").unwrap_or("")));
            }
            _ => {}
        }
    }
    // a line is three segments end to end, dashes two with a gap
    match segments {
        0 => {}
        3 => parts.push(format!("line {colour}")),
        _ => parts.push(format!("dashes {colour}")),
    }
    parts.sort();
    parts.join(" + ")
}

fn svgs(dir: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "svg"))
        .collect();
    files.sort();
    files
}

fn run(args: &[&str]) {
    let (ok, _, err) = termid(args);
    assert!(ok, "termid {}: {err}", args.join(" "));
}

#[test]
fn every_figure_kind_reads_as_a_person_would_have_it() {
    let dir = Scratch::new("figures");
    let s = |p: &Path| p.to_str().unwrap().to_string();
    // the study: Z-manoeuvres, steps (Figs. 2-4), Fig. 5, replays, predictions with tracks,
    // the spiral, the heading drift
    let study = dir.join("study");
    run(&["reproduce", "--out", &s(&study)]);
    let mut files = svgs(&study.join("figures"));
    // measured records: their preparation, the identified model's manoeuvres as simulate
    // draws them (with Monte-Carlo bands and drawn tracks), validation with a band, diagnosis
    let (prepared, validated, diagnosed) =
        (dir.join("prepared"), dir.join("validated"), dir.join("diagnosed"));
    let model = dir.join("identified.toml");
    let (ok, _, err) =
        crate::common::identify_sample_records(&model, "kalman", &["--prepared-svg", &s(&prepared)]);
    assert!(ok, "{err}");
    for (m, draws) in [("turning:35", "20"), ("zigzag:20/20", "20"), ("spiral", "0"), ("pullout:20", "0")] {
        let out = dir.join(format!("simulate_{}.svg", m.replace([':', '/'], "_")));
        run(&["simulate", "--model", &s(&model), "-m", m, "--monte-carlo", draws, "--svg", &s(&out)]);
        files.push(out);
    }
    // a model that is not a ship: its states over time, named with their units
    let generic = dir.join("simulate_duffing.svg");
    run(&[
        "simulate",
        "--model",
        "models/duffing.toml",
        "--input",
        "F=0.5",
        "--duration",
        "60",
        "--svg",
        &s(&generic),
    ]);
    files.push(generic);
    let held = "examples/data/held_out.toml";
    run(&[
        "validate",
        "--model",
        &s(&model),
        "--dataset",
        held,
        "--monte-carlo",
        "20",
        "--svg",
        &s(&validated),
    ]);
    run(&["diagnose", "--model", &s(&model), "--dataset", held, "--svg", &s(&diagnosed)]);
    for d in [&prepared, &validated, &diagnosed] {
        files.extend(svgs(d));
    }
    assert!(files.len() >= 30, "{} figures", files.len());
    // a run that moves in a plane is drawn as a track at equal scale in every figure kind
    for f in files.iter().filter(|f| {
        let n = f.file_name().unwrap().to_string_lossy();
        n.starts_with("validate_") || n.starts_with("diagnose_") || n.starts_with("predict_turning")
    }) {
        let svg = std::fs::read_to_string(f).unwrap();
        assert!(svg.contains("y0/L [-]"), "{}: no track", f.display());
    }
    let found: Vec<String> = files.iter().flat_map(|f| objections(f)).collect();
    assert!(found.is_empty(), "{} objections:\n{}", found.len(), found.join("\n"));
}

/// The reader itself, on a figure drawn to be wrong in each way it checks.
#[test]
fn the_reader_objects_to_a_bad_figure() {
    let dir = Scratch::new("figures-bad");
    let bad = r##"<svg width="400" height="300">
<line opacity="0.1" stroke="#000000" x1="50" y1="250" x2="50" y2="50"/>
<line opacity="0.1" stroke="#000000" x1="50" y1="150" x2="350" y2="150"/>
<polyline fill="none" stroke="#FF0000" points="50,60 350,60 "/>
<rect x="250" y="55" width="90" height="30" opacity="0.85" fill="#FFFFFF" stroke="none"/>
<text x="8" y="150" dy="0.76em" text-anchor="middle" font-size="10" transform="rotate(270, 8, 150)">speed</text>
<text x="200" y="100" dy="0.76em" text-anchor="middle" font-size="10">overlapping label</text>
<text x="205" y="102" dy="0.76em" text-anchor="middle" font-size="10">another label</text>
<polyline fill="none" opacity="1" stroke="#FF0000" stroke-width="2" points="10,20 17,20 "/>
<polyline fill="none" opacity="1" stroke="#FF0000" stroke-width="2" points="17,20 21,20 "/>
<polyline fill="none" opacity="1" stroke="#FF0000" stroke-width="2" points="21,20 28,20 "/>
<text x="34" y="20" dy="0.5ex" text-anchor="start" font-size="8.87">model</text>
<polyline fill="none" opacity="1" stroke="#0000FF" stroke-width="2" points="150,20 157,20 "/>
<polyline fill="none" opacity="1" stroke="#0000FF" stroke-width="2" points="161,20 168,20 "/>
<text x="174" y="20" dy="0.5ex" text-anchor="start" font-size="8.87">model</text>
</svg>"##;
    let file = dir.join("bad.svg");
    std::fs::write(&file, bad).unwrap();
    let found = objections(&file).join("\n");
    assert!(found.contains("covers data"), "{found}");
    assert!(found.contains("`overlapping label` and `another label` overlap"), "{found}");
    assert!(found.contains("the axis `speed` has no unit"), "{found}");
    assert!(found.contains("`model` is drawn as line #FF0000 and as dashes #0000FF"), "{found}");
}
