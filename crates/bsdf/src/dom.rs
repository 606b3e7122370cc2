//! A minimal element tree built with quick-xml, keeping byte offsets for error messages.

use quick_xml::events::Event;
use quick_xml::Reader;

/// One XML element: name (without namespace prefix), attributes, text and children.
#[derive(Debug, Default)]
pub struct Element {
    /// Local name.
    pub name: String,
    /// Attributes (local name, unescaped value).
    pub attrs: Vec<(String, String)>,
    /// Concatenated text content (character data and CDATA) directly inside this element.
    pub text: String,
    /// Byte offset in the document of the first text piece (or of the start tag).
    pub text_pos: usize,
    /// Byte offset of the start tag.
    pub pos: usize,
    /// Child elements in document order.
    pub children: Vec<Element>,
}

impl Element {
    /// First child with this name.
    pub fn child(&self, name: &str) -> Option<&Element> {
        self.children.iter().find(|c| c.name == name)
    }

    /// All children with this name.
    pub fn children_named<'a>(&'a self, name: &'a str) -> impl Iterator<Item = &'a Element> + 'a {
        self.children.iter().filter(move |c| c.name == name)
    }

    /// Trimmed text of the first child with this name.
    pub fn child_text(&self, name: &str) -> Option<&str> {
        self.child(name).map(|c| c.text.trim())
    }

    /// Value of an attribute.
    pub fn attr(&self, name: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }
}

/// Parses a whole document; returns the root element, or a message and byte offset.
pub fn parse(text: &str) -> Result<Element, (String, usize)> {
    let mut reader = Reader::from_str(text);
    let mut stack: Vec<Element> = vec![Element::default()];
    loop {
        let start = reader.buffer_position() as usize;
        let ev = reader.read_event().map_err(|e| {
            (
                format!("XML syntax error: {e}"),
                reader.error_position() as usize,
            )
        })?;
        match ev {
            Event::Start(ref s) | Event::Empty(ref s) => {
                let is_empty = matches!(ev, Event::Empty(_));
                let mut el = Element {
                    name: String::from_utf8_lossy(s.local_name().as_ref()).into_owned(),
                    pos: start,
                    text_pos: start,
                    ..Default::default()
                };
                for a in s.attributes() {
                    let a = a.map_err(|e| (format!("bad attribute: {e}"), start))?;
                    let v = a
                        .unescape_value()
                        .map_err(|e| (format!("bad attribute value: {e}"), start))?;
                    el.attrs.push((
                        String::from_utf8_lossy(a.key.local_name().as_ref()).into_owned(),
                        v.into_owned(),
                    ));
                }
                if is_empty {
                    stack.last_mut().expect("stack").children.push(el);
                } else {
                    stack.push(el);
                }
            }
            Event::End(_) => {
                let el = stack.pop().expect("stack");
                if stack.is_empty() {
                    return Err(("unbalanced end tag".into(), start));
                }
                stack.last_mut().expect("stack").children.push(el);
            }
            Event::Text(t) => {
                let s = t.decode().map_err(|e| (format!("bad text: {e}"), start))?;
                push_text(stack.last_mut().expect("stack"), &s, start);
            }
            Event::CData(t) => {
                let s = String::from_utf8_lossy(&t).into_owned();
                push_text(stack.last_mut().expect("stack"), &s, start);
            }
            Event::GeneralRef(r) => {
                let name = String::from_utf8_lossy(&r).into_owned();
                let s = match name.as_str() {
                    "lt" => "<".to_string(),
                    "gt" => ">".to_string(),
                    "amp" => "&".to_string(),
                    "quot" => "\"".to_string(),
                    "apos" => "'".to_string(),
                    n if n.starts_with("#x") => u32::from_str_radix(&n[2..], 16)
                        .ok()
                        .and_then(char::from_u32)
                        .map(String::from)
                        .unwrap_or_default(),
                    n if n.starts_with('#') => n[1..]
                        .parse()
                        .ok()
                        .and_then(char::from_u32)
                        .map(String::from)
                        .unwrap_or_default(),
                    _ => return Err((format!("unknown entity &{name};"), start)),
                };
                push_text(stack.last_mut().expect("stack"), &s, start);
            }
            Event::Eof => break,
            _ => {}
        }
    }
    if stack.len() != 1 {
        return Err((
            format!(
                "unexpected end of file inside <{}>",
                stack.last().map(|e| e.name.as_str()).unwrap_or("")
            ),
            text.len(),
        ));
    }
    let mut doc = stack.pop().expect("document");
    if doc.children.len() != 1 {
        return Err(("expected exactly one root element".into(), 0));
    }
    Ok(doc.children.pop().expect("root"))
}

fn push_text(el: &mut Element, s: &str, pos: usize) {
    if el.text.is_empty() {
        el.text_pos = pos;
    }
    el.text.push_str(s);
}

/// 1-based line number of a byte offset.
pub fn line_of(text: &str, pos: usize) -> usize {
    1 + text.as_bytes()[..pos.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
}
