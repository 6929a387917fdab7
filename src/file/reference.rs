#![doc = include_str!("reference.md")]
//!
//! The node and field names above are checked against the parser's own
//! list of them (the one serde derives from the file's schema) by this
//! module's tests, so the reference cannot leave one out.

#[cfg(test)]
mod tests {
    use super::super::catalogue::names;
    use super::super::schema::{FileRepr, NodeRepr};

    const REFERENCE: &str = include_str!("reference.md");

    /// Every node the parser reads, with its fields.
    fn nodes() -> Vec<(&'static str, Vec<&'static str>)> {
        names::<NodeRepr>(None)
            .into_iter()
            .enumerate()
            .map(|(i, name)| (name, names::<NodeRepr>(Some(i))))
            .collect()
    }

    /// The reference's table row of `node`.
    fn row(node: &str) -> Option<&'static str> {
        REFERENCE
            .lines()
            .find(|line| line.starts_with(&format!("| `{node}` |")))
    }

    #[test]
    fn every_node_and_field_the_parser_reads_is_in_the_reference() {
        let nodes = nodes();
        assert!(nodes.len() > 30, "{nodes:?}");
        assert!(nodes.iter().any(|(n, _)| *n == "CutPlane"), "{nodes:?}");
        for (node, fields) in &nodes {
            let row = row(node).unwrap_or_else(|| panic!("the reference has no row for `{node}`"));
            for field in fields {
                assert!(
                    row.contains(&format!("`{field}`")),
                    "the reference's row for `{node}` does not name `{field}`: {row}"
                );
            }
        }
        // The reference lists no node the parser does not read.
        let known: Vec<&str> = nodes.iter().map(|(n, _)| *n).collect();
        let sections = ["# Nodes", "# Materials"];
        let start = REFERENCE.find(sections[0]).unwrap();
        let end = REFERENCE.find(sections[1]).unwrap();
        for line in REFERENCE[start..end].lines() {
            if let Some(name) = line
                .strip_prefix("| `")
                .and_then(|rest| rest.split('`').next())
            {
                assert!(
                    known.contains(&name),
                    "`{name}` is not a node the parser reads"
                );
            }
        }
    }

    #[test]
    fn every_setting_of_a_file_is_in_the_reference() {
        let groups: [(&str, Vec<&'static str>); 7] = [
            ("# The file", names::<FileRepr>(None)),
            ("# Camera", names::<crate::scene::Camera>(None)),
            ("# Lights", names::<crate::scene::Light>(None)),
            ("# Effects", names::<crate::quality::Effects>(None)),
            (
                "# Quality",
                names::<super::super::schema::QualityRepr>(None),
            ),
            ("# Camera paths", names::<crate::animation::Keyframe>(None)),
            (
                "# Materials",
                names::<super::super::schema::MaterialRepr>(None),
            ),
        ];
        for (section, fields) in groups {
            assert!(!fields.is_empty(), "{section}");
            let start = REFERENCE.find(&format!("\n{section}\n")).unwrap();
            let rest = &REFERENCE[start + section.len() + 2..];
            let end = rest.find("\n# ").unwrap_or(rest.len());
            for field in fields {
                assert!(
                    rest[..end].contains(&format!("`{field}"))
                        || rest[..end].contains(&format!(" {field}: ")),
                    "{section} does not name `{field}`"
                );
            }
        }
    }

    #[test]
    fn the_references_examples_parse() {
        // The material and motion examples, inside a whole file.
        let material =
            "Material(material: (transparency: 1, ior: 1.5), child: Sphere(radius: 0.4))";
        assert!(REFERENCE.contains(material));
        let text = format!(
            "(version: 1, geometry: {material},\n\
             motions: [Oscillate(name: \"power\", center: 8, amplitude: 2, period: 4)])"
        );
        let err = crate::file::SceneFile::parse(&text)
            .unwrap_err()
            .to_string();
        // The motion names a parameter this scene does not have: all else read.
        assert!(err.contains("no dynamic parameter named `power`"), "{err}");
    }
}
