//! The shipped examples the page's **Examples** menu offers, compiled into the binary
//! (an installed `scnc` has no checkout beside it), and the scene a new, empty file
//! starts from. Only examples that include no other file are listed: the page's text
//! is checked beside the opened file, where their includes would not be.

/// An example: its menu name and its text.
pub(crate) struct Example {
    /// What the menu shows.
    pub(crate) name: &'static str,
    /// The scene.
    pub(crate) text: &'static str,
}

macro_rules! examples {
    ($($name:literal => $path:literal),* $(,)?) => {
        /// Every example of the menu, in its order.
        pub(crate) const EXAMPLES: &[Example] = &[
            $(Example { name: $name, text: include_str!(concat!("../../../examples/", $path)) }),*
        ];
    };
}

examples! {
    "Tour" => "tour.scn",
    "Fields" => "features/fields.scn",
    "Modelling library" => "features/library.scn",
    "Domain operations" => "features/domain.scn",
    "Profiles and sweeps" => "features/profiles.scn",
    "Procedural modelling" => "features/procedural.scn",
    "Patterns" => "features/patterns.scn",
    "Glass" => "features/glass.scn",
    "Soft shadows" => "features/soft-shadows.scn",
    "Ambient occlusion" => "features/ambient-occlusion.scn",
    "Axes" => "features/axes.scn",
    "Animation: a turntable" => "animation/orbit.scn",
}

/// What a new or empty file opens with: the README's tour.
pub(crate) const STARTER: &str = include_str!("../../../examples/tour.scn");

/// The menu as JSON: `[{name, text}]`.
pub(crate) fn json() -> serde_json::Value {
    EXAMPLES.iter().map(|e| serde_json::json!({ "name": e.name, "text": e.text })).collect()
}

#[cfg(test)]
mod tests {
    /// Every example compiles without errors on its own, as the menu puts it in a file
    /// that includes nothing.
    #[test]
    fn every_example_compiles_alone() {
        for e in super::EXAMPLES {
            let c = scnc::compile_source(
                e.name,
                std::path::Path::new("menu.scn"),
                e.text.to_string(),
                &scnc::source::FsLoader,
            );
            assert!(
                c.scene.is_some() && !c.diagnostics.iter().any(|d| d.is_error()),
                "{}: {:?}",
                e.name,
                c.diagnostics
            );
        }
    }
}
