//! Laying out written scene files for people.

/// The widest line [`layout`] writes where a value fits.
const WIDTH: usize = 80;

/// One piece of compact RON: text, or a bracketed group of comma-separated
/// items.
enum Piece {
    Text(String),
    Group(char, Vec<Vec<Piece>>, char),
}

/// Lays out compact RON (no white space) for people: a bracketed group
/// that fits on its line stays on it, a longer one gets a line per item.
pub(super) fn layout(compact: &str) -> String {
    let chars: Vec<char> = compact.chars().collect();
    let mut at = 0;
    let items = pieces(&chars, &mut at);
    let mut out = String::new();
    for item in &items {
        item_layout(item, 0, &mut out);
    }
    out
}

/// Reads items up to the closing bracket at `at` (or the end).
fn pieces(chars: &[char], at: &mut usize) -> Vec<Vec<Piece>> {
    let mut items = vec![Vec::new()];
    let mut text = String::new();
    let flush = |text: &mut String, items: &mut Vec<Vec<Piece>>| {
        if !text.is_empty() {
            items
                .last_mut()
                .expect("one item")
                .push(Piece::Text(std::mem::take(text)));
        }
    };
    while let Some(&c) = chars.get(*at) {
        *at += 1;
        match c {
            '"' => {
                text.push(c);
                while let Some(&c) = chars.get(*at) {
                    *at += 1;
                    text.push(c);
                    if c == '\\' {
                        if let Some(&next) = chars.get(*at) {
                            *at += 1;
                            text.push(next);
                        }
                    } else if c == '"' {
                        break;
                    }
                }
            }
            '(' | '[' | '{' => {
                flush(&mut text, &mut items);
                let inner = pieces(chars, at);
                let close = chars.get(*at - 1).copied().unwrap_or(')');
                items
                    .last_mut()
                    .expect("one item")
                    .push(Piece::Group(c, inner, close));
            }
            ')' | ']' | '}' => break,
            ',' => {
                flush(&mut text, &mut items);
                items.push(Vec::new());
            }
            ':' => text.push_str(": "),
            c => text.push(c),
        }
    }
    flush(&mut text, &mut items);
    items.retain(|item| !item.is_empty());
    items
}

fn flat(item: &[Piece], out: &mut String) {
    for piece in item {
        match piece {
            Piece::Text(t) => out.push_str(t),
            Piece::Group(open, items, close) => {
                out.push(*open);
                for (i, item) in items.iter().enumerate() {
                    if i > 0 {
                        out.push_str(", ");
                    }
                    flat(item, out);
                }
                out.push(*close);
            }
        }
    }
}

fn item_layout(item: &[Piece], indent: usize, out: &mut String) {
    let mut one_line = String::new();
    flat(item, &mut one_line);
    let Some((Piece::Group(open, items, close), head)) = item.split_last() else {
        out.push_str(&one_line);
        return;
    };
    if indent + one_line.chars().count() <= WIDTH || items.is_empty() {
        out.push_str(&one_line);
        return;
    }
    flat(head, out);
    out.push(*open);
    // `Union([...])`: the list opens on the variant's line.
    if let [only] = items.as_slice()
        && let [Piece::Group(inner_open, inner, inner_close)] = only.as_slice()
    {
        out.push(*inner_open);
        lines(inner, indent, out);
        out.push(*inner_close);
    } else {
        lines(items, indent, out);
    }
    out.push(*close);
}

/// `items` one per line, indented one step more than `indent`, and the
/// closing bracket's indent.
fn lines(items: &[Vec<Piece>], indent: usize, out: &mut String) {
    out.push('\n');
    for item in items {
        out.push_str(&" ".repeat(indent + 4));
        item_layout(item, indent + 4, out);
        out.push_str(",\n");
    }
    out.push_str(&" ".repeat(indent));
}
