//! Reading a world file: TOML text → `--set` overrides → serde → validation, with every error
//! pointing at a file, a line and a key.
//!
//! The file is parsed twice: once with `toml_edit`, which keeps the span of every key so that a
//! problem found later (by serde or by validation) can be traced back to its line, and once with
//! serde into [`World`]. Overrides are applied to the `toml_edit` document, so a value set on the
//! command line goes through exactly the same checks as one written in the file; an error it
//! causes names the `--set` rather than a line of the file.

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::str::FromStr;
use std::sync::Arc;

use toml_edit::{DocumentMut, Item, TableLike, Value};

use super::error::{WorldError, WorldErrors, line_column};
use super::map;
use super::schema::{Agent, LoadedMap, World};
use super::suggest::with_suggestion;
use super::validate::{validate, warnings as unlocated_warnings};

/// One `--set KEY=VALUE` override: a dotted path (array items by index) and a TOML value.
#[derive(Debug, Clone, PartialEq)]
pub struct Override {
    /// Dotted path, e.g. `agents.0.controller.b`.
    pub path: String,
    /// The value as written; parsed as TOML (`0.7`, `"gradient"`, `[1, 2]`), or taken as a
    /// bare string when it is not valid TOML (`gradient`).
    pub value: String,
}

impl FromStr for Override {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let (path, value) = s
            .split_once('=')
            .ok_or_else(|| format!("`{s}` is not KEY=VALUE"))?;
        let path = path.trim();
        if path.is_empty() || path.split('.').any(str::is_empty) {
            return Err(format!(
                "`{path}` is not a dotted key path like agents.0.controller.b"
            ));
        }
        Ok(Self {
            path: path.to_string(),
            value: value.trim().to_string(),
        })
    }
}

impl std::fmt::Display for Override {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}={}", self.path, self.value)
    }
}

/// A world file read into memory once: loaded with any overrides (a sweep loads it many
/// times), and its warnings located in the same text.
#[derive(Debug, Clone)]
pub struct WorldFile {
    path: PathBuf,
    text: String,
}

impl WorldFile {
    /// Reads the file at `path`.
    pub fn read(path: &Path) -> Result<Self, WorldErrors> {
        let text = std::fs::read_to_string(path).map_err(|e| {
            WorldErrors(vec![WorldError {
                file: path.to_path_buf(),
                location: None,
                key: None,
                message: format!("cannot read the file: {e}"),
            }])
        })?;
        Ok(Self::from_text(text, path))
    }

    /// A world file whose text is already in memory; `path` is used for messages and the
    /// default name.
    pub fn from_text(text: impl Into<String>, path: &Path) -> Self {
        Self {
            path: path.to_path_buf(),
            text: text.into(),
        }
    }

    /// The file's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The file's text, as read.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// Applies `overrides`, parses and validates. The world's `name` defaults to the file
    /// stem. Every problem found is returned, not only the first.
    pub fn load(&self, overrides: &[Override]) -> Result<World, WorldErrors> {
        load_str(&self.text, &self.path, overrides)
    }

    /// The warnings about `world`, loaded from this file (see [`super::validate::warnings`]),
    /// located in the file by key. They never stop a run; `nadf check` and `nadf run` print
    /// them.
    pub fn warnings(&self, world: &World) -> Vec<WorldError> {
        let spans = Spans::of(&self.text);
        unlocated_warnings(world)
            .into_iter()
            .map(|(key, message)| WorldError {
                file: self.path.clone(),
                location: spans
                    .span_of(&key)
                    .map(|s| line_column(&self.text, s.start)),
                key: Some(key),
                message,
            })
            .collect()
    }
}

/// Reads, overrides, parses and validates a world file: [`WorldFile::read`] then
/// [`WorldFile::load`].
///
/// ```
/// let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("worlds/room-two-dividers.toml");
/// let set: nadf::world::Override = "agents.0.controller.b=3".parse().unwrap();
/// let world = nadf::world::load(&path, &[set]).unwrap();
/// assert_eq!(world.name(), "room-two-dividers");
/// assert_eq!(world.agents[0].controller.b, Some(3.0));
/// ```
pub fn load(path: &Path, overrides: &[Override]) -> Result<World, WorldErrors> {
    WorldFile::read(path)?.load(overrides)
}

/// Like [`load`], for text already in memory; `file` is used for messages and the default name.
pub fn load_str(text: &str, file: &Path, overrides: &[Override]) -> Result<World, WorldErrors> {
    let error =
        |location: Option<(usize, usize)>, key: Option<String>, message: String| WorldError {
            file: file.to_path_buf(),
            location,
            key,
            message,
        };
    // The file as written: every error here has a line.
    let world = parse(text, file).map_err(|problems| {
        WorldErrors::in_file_order(
            problems
                .into_iter()
                .map(|p| error(p.span.map(|s| line_column(text, s.start)), p.key, p.message))
                .collect(),
        )
    })?;
    if overrides.is_empty() {
        return Ok(world);
    }
    // With the overrides: a problem is the override's when its key is (under) an overridden
    // path; otherwise it is located in the original text by its key.
    let mut doc = DocumentMut::from_str(text).expect("the text parsed above");
    for o in overrides {
        apply_override(&mut doc, o).map_err(|m| {
            WorldErrors(vec![error(
                None,
                Some(o.path.clone()),
                format!("--set {o}: {m}"),
            )])
        })?;
    }
    let edited = doc.to_string();
    parse(&edited, file).map_err(|problems| {
        let original = Spans::of(text);
        WorldErrors::in_file_order(
            problems
                .into_iter()
                .map(|p| {
                    let culprit = p.key.as_deref().and_then(|k| {
                        overrides
                            .iter()
                            .find(|o| k.starts_with(&o.path) || o.path.starts_with(k))
                    });
                    match culprit {
                        Some(o) => error(None, p.key, format!("--set {o}: {}", p.message)),
                        None => {
                            let at = p.key.as_deref().and_then(|k| original.span_of(k));
                            error(at.map(|s| line_column(text, s.start)), p.key, p.message)
                        }
                    }
                })
                .collect(),
        )
    })
}

/// A problem found while parsing or validating, located by span in the text that was parsed.
struct Problem {
    span: Option<Range<usize>>,
    key: Option<String>,
    message: String,
}

/// TOML syntax → serde → default name → validation.
fn parse(text: &str, file: &Path) -> Result<World, Vec<Problem>> {
    let doc = match toml_edit::Document::parse(text) {
        Ok(doc) => doc,
        Err(e) => {
            return Err(vec![Problem {
                span: e.span(),
                key: None,
                message: format!("TOML syntax error: {}", e.message().trim()),
            }]);
        }
    };
    let spans = Spans::from_doc(&doc);
    let mut world: World = toml::from_str(text).map_err(|e| {
        let mut span = e.span();
        let mut key = span.as_ref().and_then(|s| spans.key_at(s.start));
        let mut message = e.message().trim();
        // A message that names a field (`` `center`: … got 3``) comes from inside an
        // internally tagged wall, which serde locates at a wall's table (not always the right
        // one): it points at the first such field of the same list whose array has the length
        // the message gives.
        if let (Some(located), Some((field, rest))) = (&key, field_prefix(message))
            && let Some(len) = rest.rsplit("got ").next().and_then(first_number)
            && let Some(list) = located.split('.').next()
            && let Some((k, at)) = spans.array_of_length(&doc, list, field, len)
        {
            (key, span, message) = (Some(k), Some(at), rest);
        }
        vec![Problem {
            span,
            key,
            message: with_suggestion(message),
        }]
    })?;
    if world.name.is_none() {
        world.name = Some(
            file.file_stem()
                .map_or_else(|| "world".into(), |s| s.to_string_lossy().into_owned()),
        );
    }
    let given = |key: &str| doc.as_table().contains_key(key);
    if let Some(settings) = &world.map {
        let base = file.parent().unwrap_or(Path::new(""));
        let occupancy = map::read(settings, base).map_err(|e| {
            vec![Problem {
                span: spans.span_of("map.file"),
                key: Some("map.file".into()),
                message: e.to_string(),
            }]
        })?;
        if !given("size") {
            world.size = occupancy.extent();
        }
        if !given("origin") {
            world.origin = occupancy.origin;
        }
        let walls = map::rectangles(&occupancy);
        world.loaded_map = Some(Arc::new(LoadedMap { occupancy, walls }));
    } else if !given("size") {
        return Err(vec![Problem {
            span: None,
            key: Some("size".into()),
            message: "missing field `size` (the box's width and height, m; a world with a [map] takes the map's)".into(),
        }]);
    }
    let issues = validate(&world);
    if issues.is_empty() {
        let mut world = world;
        // A shaped agent is planned in (x, y, θ) and simulated by its own kind of run: the
        // agents every other part of the sandbox handles stay discs.
        let (shaped, discs) = std::mem::take(&mut world.agents)
            .into_iter()
            .partition(Agent::is_shaped);
        (world.agents, world.shaped) = (discs, shaped);
        // A robot on wheels is steered by its look-ahead point (`sim::drive`): every part of
        // the sandbox that plans for a disc plans for that point, with a disc grown by the
        // look-ahead that holds the whole robot at any heading.
        for agent in &mut world.agents {
            if let Some(drive) = &mut agent.drive {
                let l = drive.lookahead_for(agent.radius);
                drive.lookahead = Some(l);
                drive.body_radius = agent.radius;
                let (s, c) = agent.heading.sin_cos();
                agent.start = [agent.start[0] + l * c, agent.start[1] + l * s];
                agent.radius += l;
                // The point's speed limit: the fastest it may move in any direction with both
                // wheels within theirs, so that the wheels can always still turn it.
                if agent.controller.kind != crate::world::ControllerKind::Unicycle {
                    let v = drive.point_speed(l);
                    let limit = agent.controller.speed_limit.map_or(v, |u| u.min(v));
                    agent.controller.speed_limit = Some(limit);
                }
            }
        }
        Ok(world)
    } else {
        Err(issues
            .into_iter()
            .map(|(key, message)| Problem {
                span: spans.span_of(&key),
                key: Some(key),
                message,
            })
            .collect())
    }
}

/// The span of every key path in a TOML document (`agents.0.controller.b`).
struct Spans(Vec<(String, Range<usize>)>);

impl Spans {
    fn of(text: &str) -> Self {
        toml_edit::Document::parse(text).map_or(Spans(Vec::new()), |d| Self::from_doc(&d))
    }

    fn from_doc(doc: &toml_edit::Document<&str>) -> Self {
        let mut out = Vec::new();
        walk_table(doc.as_table(), "", &mut out);
        Spans(out)
    }

    /// The innermost key whose span contains `offset`.
    fn key_at(&self, offset: usize) -> Option<String> {
        self.0
            .iter()
            .filter(|(_, r)| r.start <= offset && offset < r.end.max(r.start + 1))
            .min_by_key(|(_, r)| r.len())
            .map(|(k, _)| k.clone())
    }

    /// The first key under `list` that is an item of `field` (a point of a polygon) or
    /// `field` itself, in that order of preference, and holds an array of `len` items in `doc`.
    fn array_of_length(
        &self,
        doc: &toml_edit::Document<&str>,
        list: &str,
        field: &str,
        len: usize,
    ) -> Option<(String, Range<usize>)> {
        let under = |k: &str| {
            k.strip_prefix(list)
                .is_some_and(|rest| rest.starts_with('.'))
        };
        let item_of_field = |k: &str| {
            let mut segments = k.rsplit('.');
            segments.next().is_some_and(|l| l.parse::<usize>().is_ok())
                && segments.next() == Some(field)
        };
        let is_field = |k: &str| k.rsplit('.').next() == Some(field);
        [&item_of_field as &dyn Fn(&str) -> bool, &is_field]
            .into_iter()
            .find_map(|matches| {
                self.0
                    .iter()
                    .find(|(k, _)| under(k) && matches(k) && array_len(doc, k) == Some(len))
            })
            .cloned()
    }

    /// The span of `path`, or of its nearest ancestor in the document.
    fn span_of(&self, path: &str) -> Option<Range<usize>> {
        let mut path = path;
        loop {
            if let Some((_, r)) = self.0.iter().find(|(k, _)| k == path) {
                return Some(r.clone());
            }
            path = &path[..path.rfind('.')?];
        }
    }
}

/// The whole number at the start of `text`.
fn first_number(text: &str) -> Option<usize> {
    let digits: String = text.chars().take_while(char::is_ascii_digit).collect();
    digits.parse().ok()
}

/// The number of items of the array at the dotted `path` of `doc`, if there is one.
fn array_len(doc: &toml_edit::Document<&str>, path: &str) -> Option<usize> {
    enum Node<'a> {
        Table(&'a dyn TableLike),
        Item(&'a Item),
        Value(&'a Value),
    }
    let mut node = Node::Table(doc.as_table());
    for segment in path.split('.') {
        let index = || segment.parse::<usize>().ok();
        node = match node {
            Node::Table(t) => Node::Item(t.get(segment)?),
            Node::Item(Item::Table(t)) => Node::Item(t.get(segment)?),
            Node::Item(Item::ArrayOfTables(a)) => Node::Table(a.get(index()?)?),
            Node::Item(Item::Value(v)) | Node::Value(v) => match v {
                Value::Array(a) => Node::Value(a.get(index()?)?),
                Value::InlineTable(t) => Node::Value(t.get(segment)?),
                _ => return None,
            },
            Node::Item(Item::None) => return None,
        };
    }
    match node {
        Node::Item(Item::Value(Value::Array(a))) | Node::Value(Value::Array(a)) => Some(a.len()),
        _ => None,
    }
}

/// `` `field`: rest `` → `(field, rest)`.
fn field_prefix(message: &str) -> Option<(&str, &str)> {
    let (field, rest) = message.strip_prefix('`')?.split_once("`: ")?;
    (!field.is_empty() && field.chars().all(|c| c.is_ascii_alphanumeric() || c == '_'))
        .then_some((field, rest))
}

fn join(prefix: &str, key: &str) -> String {
    if prefix.is_empty() {
        key.to_string()
    } else {
        format!("{prefix}.{key}")
    }
}

fn walk_table(table: &dyn TableLike, prefix: &str, out: &mut Vec<(String, Range<usize>)>) {
    for (name, item) in table.iter() {
        let path = join(prefix, name);
        let key_span = table.key(name).and_then(|k| k.span());
        walk_item(item, &path, key_span, out);
    }
}

fn walk_item(
    item: &Item,
    path: &str,
    key_span: Option<Range<usize>>,
    out: &mut Vec<(String, Range<usize>)>,
) {
    let with_key = |span: Option<Range<usize>>| match (key_span.clone(), span) {
        (Some(k), Some(v)) => Some(k.start.min(v.start)..k.end.max(v.end)),
        (k, v) => v.or(k),
    };
    match item {
        Item::None => {}
        Item::Value(value) => walk_value(value, path, with_key(value.span()), out),
        Item::Table(t) => {
            if let Some(span) = with_key(t.span()) {
                out.push((path.to_string(), span));
            }
            walk_table(t, path, out);
        }
        Item::ArrayOfTables(a) => {
            for (i, t) in a.iter().enumerate() {
                let path = format!("{path}.{i}");
                if let Some(span) = t.span() {
                    out.push((path.clone(), span));
                }
                walk_table(t, &path, out);
            }
        }
    }
}

fn walk_value(
    value: &Value,
    path: &str,
    span: Option<Range<usize>>,
    out: &mut Vec<(String, Range<usize>)>,
) {
    if let Some(span) = span {
        out.push((path.to_string(), span));
    }
    match value {
        Value::InlineTable(t) => walk_table(t, path, out),
        Value::Array(a) => {
            for (i, v) in a.iter().enumerate() {
                walk_value(v, &format!("{path}.{i}"), v.span(), out);
            }
        }
        _ => {}
    }
}

/// Sets `o.path` to `o.value` in the document. Tables on the way are created when missing (so
/// `field.guidance` works in a file without `[field]`); array items must exist.
fn apply_override(doc: &mut DocumentMut, o: &Override) -> Result<(), String> {
    let value = parse_value(&o.value);
    let segments: Vec<&str> = o.path.split('.').collect();
    set_in_table(doc.as_table_mut(), &segments, value)
}

fn parse_value(text: &str) -> Value {
    format!("v = {text}")
        .parse::<DocumentMut>()
        .ok()
        .and_then(|d| d.get("v").and_then(|i| i.as_value().cloned()))
        .unwrap_or_else(|| Value::from(text))
}

fn set_in_table(table: &mut dyn TableLike, segments: &[&str], value: Value) -> Result<(), String> {
    let (head, rest) = segments.split_first().ok_or("empty key path")?;
    if rest.is_empty() {
        table.insert(head, Item::Value(value));
        return Ok(());
    }
    if table.get(head).is_none() {
        if rest[0].parse::<usize>().is_ok() {
            return Err(format!("there is no array `{head}` to index"));
        }
        let mut new = toml_edit::Table::new();
        new.set_implicit(true);
        table.insert(head, Item::Table(new));
    }
    let item = table.get_mut(head).expect("inserted above");
    set_in_item(item, head, rest, value)
}

fn set_in_item(item: &mut Item, name: &str, segments: &[&str], value: Value) -> Result<(), String> {
    let index = || -> Result<usize, String> {
        segments[0].parse().map_err(|_| {
            format!(
                "`{name}` is an array: index it with a number, not `{}`",
                segments[0]
            )
        })
    };
    match item {
        Item::Table(t) => set_in_table(t, segments, value),
        Item::Value(Value::InlineTable(t)) => set_in_table(t, segments, value),
        Item::ArrayOfTables(a) => {
            let (i, len) = (index()?, a.len());
            let t = a
                .get_mut(i)
                .ok_or_else(|| format!("`{name}` has {len} items, there is no item {i}"))?;
            if segments.len() == 1 {
                return Err(format!("`{name}.{i}` is a table: set one of its keys"));
            }
            set_in_table(t, &segments[1..], value)
        }
        Item::Value(Value::Array(a)) => {
            let (i, len) = (index()?, a.len());
            if i >= len {
                return Err(format!("`{name}` has {len} items, there is no item {i}"));
            }
            if segments.len() == 1 {
                a.replace(i, value);
                return Ok(());
            }
            match a.get_mut(i) {
                Some(Value::InlineTable(t)) => set_in_table(t, &segments[1..], value),
                _ => Err(format!("`{name}.{i}` is a value, not a table")),
            }
        }
        _ => Err(format!("`{name}` is a value, not a table")),
    }
}
