//! Reading back the SVG figures the program writes: the text of every `<text>` element
//! and the content of a named element, decoded as the figure writer encodes them
//! ([`langevin_fem::output::figure::xml_unescape`]).

use langevin_fem::output::figure::xml_unescape;

/// The text content of every `<text>` element, trimmed and unescaped.
pub fn svg_texts(svg: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = svg;
    while let Some(start) = rest.find("<text") {
        rest = &rest[start..];
        let open_end = rest.find('>').expect("text tag closed");
        let close = rest.find("</text>").expect("text element closed");
        out.push(xml_unescape(rest[open_end + 1..close].trim()));
        rest = &rest[close..];
    }
    out
}

/// The content of the first `<tag>…</tag>` element, unescaped.
pub fn element(svg: &str, tag: &str) -> Option<String> {
    let open = format!("<{tag}>");
    let start = svg.find(&open)? + open.len();
    let end = svg[start..].find(&format!("</{tag}>"))? + start;
    Some(xml_unescape(&svg[start..end]))
}
