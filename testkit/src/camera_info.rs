//! A depth camera's calibration from a ROS `sensor_msgs/CameraInfo` YAML file: the message as
//! `rostopic echo -n1 .../camera_info` (ROS 1: `width`, `height`, `K: [...]`) or `ros2 topic echo
//! --once` (ROS 2: `k:` followed by `- ...` items) print it, or a `camera_calibration` file
//! (`image_width`, `image_height`, `camera_matrix: {rows: 3, cols: 3, data: [...]}`).
//!
//! A small hand-written reader of the YAML these tools write: block and flow mappings, scalars,
//! lists of scalars (block `- x` items or flow `[x, y]`, which may span lines), comments, and the
//! first document of a stream. Anchors, tags, multi-line strings and lists of mappings are not
//! read. Only `width`, `height` and `K` are used: distortion is not applied (the depth image
//! must be rectified, as a depth camera's usually is), and `R` and `P` are ignored.

use std::collections::BTreeMap;

use super::Result;
use super::raw::Pinhole;

/// What the tool takes from a camera info file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraInfo {
    /// Image size, pixels.
    pub width: u32,
    pub height: u32,
    pub pinhole: Pinhole,
}

impl CameraInfo {
    /// Read the message or calibration-file form; the error says what is missing or malformed.
    pub fn parse(text: &str) -> Result<Self> {
        let values = read_yaml(text)?;
        let width = whole(&values, &["width", "image_width"])?;
        let height = whole(&values, &["height", "image_height"])?;
        let (name, k) = camera_matrix(&values)?;
        let [fx, skew, cx, k3, fy, cy, k6, k7, k8] = k;
        let pinhole = Pinhole::new(fx, fy, cx, cy).map_err(|e| format!("{name}: {e}"))?;
        if [skew, k3, k6, k7] != [0.0; 4] || k8 != 1.0 {
            return Err(format!(
                "{name} is {k:?}, not of the form [fx, 0, cx, 0, fy, cy, 0, 0, 1] (a camera \
                 with skew is not supported)"
            ));
        }
        Ok(Self {
            width,
            height,
            pinhole,
        })
    }
}

/// A scalar (quotes removed) or a list of scalars.
#[derive(Clone, Debug, PartialEq)]
enum Value {
    Scalar(String),
    List(Vec<String>),
}

/// Every value of a document by its dotted key path (`width`, `roi.width`, `camera_matrix.data`).
type Values = BTreeMap<String, Value>;

/// The value of the first of `keys` present, with that key; an error when none is, or when
/// another is present too (which one the writer meant is then unclear).
fn one_of<'a>(values: &'a Values, keys: &[&'a str]) -> Result<(&'a str, &'a Value)> {
    let mut present = keys.iter().filter_map(|&k| values.get(k).map(|v| (k, v)));
    match (present.next(), present.next()) {
        (Some(found), None) => Ok(found),
        (Some((first, _)), Some((second, _))) => Err(format!("both {first} and {second} given")),
        (None, _) => Err(format!("no {}", keys.join(" or "))),
    }
}

/// An image size: a whole number of pixels.
fn whole(values: &Values, keys: &[&str]) -> Result<u32> {
    match one_of(values, keys)? {
        (key, Value::Scalar(text)) => text
            .parse()
            .map_err(|_| format!("{key} is {text:?}, not a whole number of pixels")),
        (key, Value::List(_)) => Err(format!("{key} is a list, not a number of pixels")),
    }
}

/// `K` (ROS 1), `k` (ROS 2) or `camera_matrix.data` (a calibration file): the 3x3 camera
/// matrix, row-major, with the key it was found under.
fn camera_matrix(values: &Values) -> Result<(&str, [f32; 9])> {
    let (key, value) = one_of(values, &["K", "k", "camera_matrix.data"])?;
    let Value::List(items) = value else {
        return Err(format!("{key} is not a list of nine numbers"));
    };
    let mut numbers = [0.0; 9];
    if items.len() != numbers.len() {
        return Err(format!(
            "{key} has {} elements, expected 9: [fx, 0, cx, 0, fy, cy, 0, 0, 1]",
            items.len()
        ));
    }
    for (i, (slot, text)) in numbers.iter_mut().zip(items).enumerate() {
        *slot = super::raw::number(text)
            .ok_or_else(|| format!("{key}[{i}] is {text:?}, not a finite number"))?;
    }
    Ok((key, numbers))
}

/// Read the first document of `text` (see the module doc for the subset read).
fn read_yaml(text: &str) -> Result<Values> {
    let mut reader = Reader::default();
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut lines = text.lines().enumerate().map(|(i, line)| (i + 1, line));
    while let Some((number, line)) = lines.next() {
        let line = strip_comment(line).trim_end();
        match line.trim_start() {
            "" => {}
            directive if directive.starts_with('%') => {}
            "---" if reader.levels.is_empty() && reader.values.is_empty() => {}
            "---" | "..." => break,
            _ => reader
                .line(line, &mut lines)
                .map_err(|e| format!("line {number}: {e}"))?,
        }
    }
    Ok(reader.values)
}

/// The state of a block-structured read, line by line.
#[derive(Default)]
struct Reader {
    values: Values,
    /// The mappings the current line may belong to: their keys' indentation and path prefix
    /// (`""` at the top, `"roi."` inside `roi:`), outermost first.
    levels: Vec<(usize, String)>,
    /// The last key with nothing after its colon, and its indentation: a nested mapping or a
    /// list follows.
    open: Option<(usize, String)>,
    /// The list being read (its path and its items' indentation).
    list: Option<(String, usize)>,
}

impl Reader {
    /// Read one line (`rest` for a flow collection that goes on).
    fn line<'a>(
        &mut self,
        line: &'a str,
        rest: &mut impl Iterator<Item = (usize, &'a str)>,
    ) -> Result<()> {
        let content = line.trim_start_matches(' ');
        let indent = line.len() - content.len();
        if content.starts_with('\t') {
            return Err("a tab in the indentation".into());
        }
        if let Some(item) = content
            .strip_prefix("- ")
            .or((content == "-").then_some(""))
        {
            return self.item(indent, item.trim());
        }
        self.list = None;
        if content.starts_with('{') && self.levels.is_empty() {
            return store(&mut self.values, String::new(), &gather(content, rest)?, 0);
        }
        self.entry(indent, content, rest)
    }

    /// A `key: value` or `key:` line.
    fn entry<'a>(
        &mut self,
        indent: usize,
        content: &'a str,
        rest: &mut impl Iterator<Item = (usize, &'a str)>,
    ) -> Result<()> {
        let (key, value) = split_key(content)
            .ok_or_else(|| format!("expected `key: value`, found {content:?}"))?;
        let path = self.path(indent, key)?;
        let value = value.trim();
        if value.starts_with(['!', '&', '*', '|', '>']) {
            return Err(format!(
                "{key}: {value:?} is a tag, anchor, alias or block string, which are not read"
            ));
        }
        if value.is_empty() {
            check_new(&self.values, &path)?;
            self.open = Some((indent, path));
            return Ok(());
        }
        self.open = None;
        store(&mut self.values, path, &gather(value, rest)?, 0)
    }

    /// The path of `key` at `indent`: a sibling of an earlier key, or the first key inside the
    /// open one.
    fn path(&mut self, indent: usize, key: &str) -> Result<String> {
        while self.levels.len() > 1 && self.levels.last().is_some_and(|(i, _)| *i > indent) {
            self.levels.pop();
        }
        match (self.levels.last(), self.open.take()) {
            (Some((i, prefix)), _) if *i == indent => return Ok(format!("{prefix}{key}")),
            (None, None) => self.levels.push((indent, String::new())),
            (Some((i, _)), Some((open, path))) if *i == open => {
                self.levels.push((indent, format!("{path}.")));
            }
            _ => return Err(format!("{key:?} is indented unlike the keys above it")),
        }
        self.path(indent, key)
    }

    /// A `- item` line: the next element of the list under the open key.
    fn item(&mut self, indent: usize, item: &str) -> Result<()> {
        if let Some((open, path)) = self.open.take() {
            if indent < open {
                return Err(format!("a list item left of its key {path:?}"));
            }
            self.values.insert(path.clone(), Value::List(Vec::new()));
            self.list = Some((path, indent));
        }
        match &self.list {
            Some((path, i)) if *i == indent => {
                if let Some(Value::List(items)) = self.values.get_mut(path) {
                    items.push(unquote(item).into());
                }
                Ok(())
            }
            _ => Err(format!("a list item {item:?} outside a list")),
        }
    }
}

/// `key: value` (or `key:`) split at the colon; `None` for anything else.
fn split_key(content: &str) -> Option<(&str, &str)> {
    let (key, value) = content.split_once(':')?;
    let plain = !key.is_empty() && !key.starts_with(['"', '\'', '[', '{', '-']);
    (plain && (value.is_empty() || value.starts_with(' '))).then_some((key.trim_end(), value))
}

/// Fail when `path` already has a value (a key given twice).
fn check_new(values: &Values, path: &str) -> Result<()> {
    match values.contains_key(path) {
        true => Err(format!("{path} given twice")),
        false => Ok(()),
    }
}

/// `value`, with the lines after it while the flow collection it starts (`[...]`, `{...}`) is
/// open.
fn gather<'a>(value: &str, rest: &mut impl Iterator<Item = (usize, &'a str)>) -> Result<String> {
    let mut text = value.to_string();
    let mut open = if value.starts_with(['[', '{']) {
        brackets(value)
    } else {
        0
    };
    while open > 0 {
        let (_, next) = rest
            .next()
            .ok_or_else(|| format!("{value:?} is not closed"))?;
        let next = strip_comment(next).trim();
        open += brackets(next);
        text.push(' ');
        text.push_str(next);
    }
    Ok(text)
}

/// Brackets opened minus brackets closed in `text`, outside quotes.
fn brackets(text: &str) -> i64 {
    let change = |(_, c)| match c {
        '[' | '{' => 1,
        ']' | '}' => -1,
        _ => 0,
    };
    unquoted(text).into_iter().map(change).sum()
}

/// How deep flow mappings may nest: a camera info file nests them 3 deep at most; a file that
/// nests them far deeper is not one, and is refused before the recursion exhausts the stack.
const MAX_FLOW_NESTING: usize = 32;

/// Store a scalar or flow collection under `path` (a flow mapping's entries under `path.key`),
/// `nesting` flow mappings deep.
fn store(values: &mut Values, path: String, text: &str, nesting: usize) -> Result<()> {
    let text = text.trim();
    let close = match text.chars().next() {
        Some('[') => ']',
        Some('{') => '}',
        _ => {
            check_new(values, &path)?;
            values.insert(path, Value::Scalar(unquote(text).into()));
            return Ok(());
        }
    };
    if closing(text) != Some(text.len() - 1) || !text.ends_with(close) {
        return Err(format!("text after the closing bracket in {text:?}"));
    }
    let entries = split_top_level(&text[1..text.len() - 1]);
    if close == ']' {
        check_new(values, &path)?;
        let items = entries.iter().map(|e| unquote(e.trim()).to_string());
        values.insert(path, Value::List(items.collect()));
        return Ok(());
    }
    if nesting == MAX_FLOW_NESTING {
        return Err(format!(
            "flow mappings nested deeper than {MAX_FLOW_NESTING}"
        ));
    }
    let prefix = if path.is_empty() { path } else { path + "." };
    for entry in entries.iter().map(|e| e.trim()).filter(|e| !e.is_empty()) {
        let (key, value) =
            split_key(entry).ok_or_else(|| format!("expected `key: value`, found {entry:?}"))?;
        store(values, format!("{prefix}{key}"), value, nesting + 1)?;
    }
    Ok(())
}

/// The characters of `text` outside quoted scalars, with their byte offsets. A quote opens a
/// quoted scalar only where a scalar may start, so the `'` of `it's` is plain text.
fn unquoted(text: &str) -> Vec<(usize, char)> {
    let mut outside = Vec::new();
    let (mut quote, mut previous) = (None, ' ');
    for (i, c) in text.char_indices() {
        match quote {
            Some(q) if c == q => quote = None,
            Some(_) => {}
            None if matches!(c, '"' | '\'')
                && (previous.is_whitespace() || "[{,:".contains(previous)) =>
            {
                quote = Some(c);
            }
            None => outside.push((i, c)),
        }
        previous = c;
    }
    outside
}

/// `line` up to a comment (a `#` at the start or after a space, outside quotes).
fn strip_comment(line: &str) -> &str {
    let starts_comment = |&(i, c): &(usize, char)| {
        c == '#'
            && line[..i]
                .chars()
                .next_back()
                .is_none_or(char::is_whitespace)
    };
    match unquoted(line).into_iter().find(starts_comment) {
        Some((i, _)) => &line[..i],
        None => line,
    }
}

/// The byte offset of the bracket that closes the one `text` starts with, outside quotes.
fn closing(text: &str) -> Option<usize> {
    let mut depth = 0;
    for (i, c) in unquoted(text) {
        match c {
            '[' | '{' => depth += 1,
            ']' | '}' if depth == 1 => return Some(i),
            ']' | '}' => depth -= 1,
            _ => {}
        }
    }
    None
}

/// The comma-separated entries of a flow collection's inside, nested collections kept whole;
/// none for an empty inside.
fn split_top_level(inner: &str) -> Vec<&str> {
    if inner.trim().is_empty() {
        return Vec::new();
    }
    let (mut entries, mut start, mut depth) = (Vec::new(), 0, 0);
    for (i, c) in unquoted(inner) {
        match c {
            '[' | '{' => depth += 1,
            ']' | '}' => depth -= 1,
            ',' if depth == 0 => {
                entries.push(&inner[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    entries.push(&inner[start..]);
    entries
}

/// A scalar without its enclosing quotes (no escapes are needed for what is read).
fn unquote(text: &str) -> &str {
    for quote in ['"', '\''] {
        if let Some(inner) = text.strip_prefix(quote).and_then(|t| t.strip_suffix(quote)) {
            return inner;
        }
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The committed fixture: the development scenes' camera as `rostopic echo` prints it.
    const FIXTURE: &str = include_str!("../data/camera_info_320x240.yaml");

    fn pinhole(fx: f32, fy: f32, cx: f32, cy: f32) -> Pinhole {
        Pinhole::new(fx, fy, cx, cy).unwrap()
    }

    fn error(text: &str) -> String {
        CameraInfo::parse(text).unwrap_err()
    }

    #[test]
    fn reads_the_ros1_message_of_the_fixture() {
        let info = CameraInfo::parse(FIXTURE).unwrap();
        assert_eq!(
            info,
            CameraInfo {
                width: 320,
                height: 240,
                pinhole: pinhole(285.0, 285.0, 159.5, 119.5),
            }
        );
        let values = read_yaml(FIXTURE).unwrap();
        assert_eq!(values["roi.width"], Value::Scalar("0".into()));
        assert_eq!(
            values["header.stamp.secs"],
            Value::Scalar("1700000000".into())
        );
        assert_eq!(
            values["header.frame_id"],
            Value::Scalar("camera_depth_optical_frame".into())
        );
    }

    #[test]
    fn reads_the_ros2_message_with_block_lists() {
        let text = "header:\n  stamp:\n    sec: 1\n    nanosec: 2\n  frame_id: depth\n\
                    height: 3\nwidth: 4\ndistortion_model: plumb_bob\nd:\n- 0.0\n- 0.0\n\
                    k:\n- 5.0\n- 0.0\n- 1.5\n- 0.0\n- 6.0\n- 1.0\n- 0.0\n- 0.0\n- 1.0\n\
                    r:\n  - 1.0\nbinning_x: 0\nroi:\n  x_offset: 0\n  do_rectify: false\n---\n";
        let info = CameraInfo::parse(text).unwrap();
        assert_eq!((info.width, info.height), (4, 3));
        assert_eq!(info.pinhole, pinhole(5.0, 6.0, 1.5, 1.0));
        let values = read_yaml(text).unwrap();
        assert_eq!(values["d"], Value::List(vec!["0.0".into(), "0.0".into()]));
        assert_eq!(values["r"], Value::List(vec!["1.0".into()]));
    }

    #[test]
    fn reads_the_calibration_file_in_block_and_flow_style() {
        let block = "image_width: 640  # pixels\nimage_height: 480\ncamera_name: 'depth'\n\
                     camera_matrix:\n  rows: 3\n  cols: 3\n  data: [525, 0., 319.5,\n    \
                     0, 5.25e+02, 239.5, 0, 0, 1]\ndistortion_coefficients:\n  rows: 1\n  \
                     cols: 5\n  data: [0, 0, 0, 0, 0]\n";
        let flow = "%YAML 1.2\n---\nimage_width: 640\nimage_height: 480\n\
                    camera_matrix: {rows: 3, cols: 3,  # a flow mapping on two lines\n  \
                    data: [525, 0, 319.5, 0, 525, 239.5, 0, 0, 1]}\n";
        for text in [block, flow] {
            let info = CameraInfo::parse(text).unwrap();
            assert_eq!((info.width, info.height), (640, 480));
            assert_eq!(info.pinhole, pinhole(525.0, 525.0, 319.5, 239.5));
        }
    }

    #[test]
    fn reads_a_document_that_is_one_flow_mapping() {
        let text = "{height: 3, width: 4, k: [5, 0, 1.5, 0, 6, 1, 0, 0, 1], roi: {width: 0}}";
        let info = CameraInfo::parse(text).unwrap();
        assert_eq!((info.width, info.pinhole), (4, pinhole(5.0, 6.0, 1.5, 1.0)));
    }

    #[test]
    fn rejects_a_missing_or_malformed_camera_matrix() {
        let head = "width: 4\nheight: 3\n";
        let with = |k: &str| error(&format!("{head}{k}\n"));
        assert_eq!(with(""), "no K or k or camera_matrix.data");
        assert_eq!(
            with("K: [5, 0, 1.5, 0, 6, 1, 0, 0]"),
            "K has 8 elements, expected 9: [fx, 0, cx, 0, fy, cy, 0, 0, 1]"
        );
        assert_eq!(
            with("K: [5, 0, 1.5, 0, six, 1, 0, 0, 1]"),
            "K[4] is \"six\", not a finite number"
        );
        assert_eq!(with("K: 5"), "K is not a list of nine numbers");
        assert!(with("K: [5, 0.5, 1.5, 0, 6, 1, 0, 0, 1]").contains("skew is not supported"));
        assert_eq!(
            with("K: [0, 0, 0, 0, 0, 0, 0, 0, 0]"),
            "K: focal length fx = 0 must be positive and finite"
        );
        assert_eq!(
            with("K: [5, 0, 1.5, 0, 6, 1, 0, 0, 1]\nk: [5, 0, 1.5, 0, 6, 1, 0, 0, 1]"),
            "both K and k given"
        );
    }

    #[test]
    fn rejects_a_missing_or_malformed_size() {
        let k = "K: [5, 0, 1.5, 0, 6, 1, 0, 0, 1]\n";
        assert_eq!(error(&format!("height: 3\n{k}")), "no width or image_width");
        assert_eq!(
            error(&format!("width: 4.5\nheight: 3\n{k}")),
            "width is \"4.5\", not a whole number of pixels"
        );
        assert_eq!(
            error(&format!("width: [4]\nheight: 3\n{k}")),
            "width is a list, not a number of pixels"
        );
    }

    #[test]
    fn rejects_malformed_yaml_with_its_line() {
        let error = |text: &str| read_yaml(text).unwrap_err();
        assert_eq!(error("width: 4\nwidth: 5"), "line 2: width given twice");
        assert_eq!(
            error("a:\n  b: 1\n c: 2"),
            "line 3: \"c\" is indented unlike the keys above it"
        );
        assert_eq!(
            error("a: 1\n  b: 2"),
            "line 2: \"b\" is indented unlike the keys above it"
        );
        assert_eq!(error("K: [1, 2,\n 3"), "line 1: \"[1, 2,\" is not closed");
        assert_eq!(
            error("K: [1, 2]]"),
            "line 1: text after the closing bracket in \"[1, 2]]\""
        );
        assert_eq!(
            error("K: [1, 2}"),
            "line 1: text after the closing bracket in \"[1, 2}\""
        );
        assert_eq!(
            error("K: [1, 2] x"),
            "line 1: text after the closing bracket in \"[1, 2] x\""
        );
        assert_eq!(
            error("width 4"),
            "line 1: expected `key: value`, found \"width 4\""
        );
        assert_eq!(error("- 1"), "line 1: a list item \"1\" outside a list");
        assert_eq!(error("\twidth: 4"), "line 1: a tab in the indentation");
        assert_eq!(
            error("camera_matrix: !!opencv-matrix"),
            "line 1: camera_matrix: \"!!opencv-matrix\" is a tag, anchor, alias or block \
             string, which are not read"
        );
        assert_eq!(
            error("  a: 1\nb: 2"),
            "line 2: \"b\" is indented unlike the keys above it"
        );
    }

    #[test]
    fn never_panics_on_a_damaged_file() {
        let deep = format!("a: {}{}", "{b: ".repeat(100_000), "}".repeat(100_000));
        assert!(
            read_yaml(&deep)
                .unwrap_err()
                .contains("nested deeper than 32")
        );
        let unclosed = format!("K: [{}", "1,\n".repeat(100_000));
        assert_eq!(
            read_yaml(&unclosed).unwrap_err(),
            "line 1: \"[1,\" is not closed"
        );
        let mut damaged = 0;
        for (i, _) in FIXTURE.char_indices() {
            let (head, tail) = FIXTURE.split_at(i);
            let tail = &tail[tail.chars().next().map_or(0, char::len_utf8)..];
            let _ = CameraInfo::parse(&format!("{head}{tail}"));
            for inserted in [
                "[", "]", "{", "}", ":", "- ", "#", "'", "\"", "\t", ",", "\n",
            ] {
                damaged += CameraInfo::parse(&format!("{head}{inserted}{tail}")).is_err() as u32;
            }
        }
        assert!(damaged > 0);
    }

    #[test]
    fn comments_quotes_and_later_documents_are_handled() {
        let text =
            "\u{feff}# a camera\r\nframe_id: \"a # b\"  # the frame\nname: it's\n---\nwidth: 9\n";
        let values = read_yaml(text).unwrap();
        assert_eq!(values["frame_id"], Value::Scalar("a # b".into()));
        assert_eq!(values["name"], Value::Scalar("it's".into()));
        assert!(!values.contains_key("width"));
    }
}
