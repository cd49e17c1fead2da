//! Words people bring from other tools (OpenSCAD, POV-Ray, shader languages), and what
//! scnc writes instead. One table, read by the parser (a word where a statement or `at`
//! was expected) and by the checker (an unknown function or name), so every place that
//! meets `translate` gives the same advice.

/// What a word from another tool is called in scnc.
#[derive(Debug)]
pub struct Guess {
    /// The word as written elsewhere.
    pub word: &'static str,
    /// scnc's word for it, offered as a machine-applicable replacement when the word can
    /// simply be swapped (`cube` → `box`), `None` where the form differs too.
    pub replacement: Option<&'static str>,
    /// The advice, phrased as a hint.
    pub hint: &'static str,
}

const PLACE: &str = "scnc places a shape with `at` after it: `box(1) at [x, y, z]`";
const COLOUR: &str = "a colour belongs to a material: `… with material(color = #ff0000)`";

/// Every word with advice.
pub const GUESSES: &[Guess] = &[
    Guess { word: "colour", replacement: None, hint: COLOUR },
    Guess { word: "color", replacement: None, hint: COLOUR },
    Guess {
        word: "cube",
        replacement: Some("box"),
        hint: "scnc's `box(s)` is centred, `s` its half-size: OpenSCAD's `cube(1)` is `box(0.5) at [0.5, 0.5, 0.5]`",
    },
    Guess { word: "cuboid", replacement: Some("box"), hint: "`box(x, y, z)` takes half-sizes and is centred" },
    Guess { word: "difference", replacement: Some("subtract"), hint: "`subtract(a, b, …)` keeps `a` less the rest" },
    Guess { word: "intersection", replacement: Some("intersect"), hint: "`intersect(a, b, …)` keeps what all share" },
    Guess {
        word: "linear_extrude",
        replacement: Some("extrude"),
        hint: "`extrude(profile, half_height)` extrudes along y, centred on its profile",
    },
    Guess { word: "move", replacement: Some("at"), hint: PLACE },
    Guess { word: "moveto", replacement: Some("at"), hint: PLACE },
    Guess { word: "position", replacement: Some("at"), hint: PLACE },
    Guess { word: "rotate_extrude", replacement: Some("revolve"), hint: "`revolve(profile)` turns a profile about y" },
    Guess { word: "square", replacement: Some("rect"), hint: "`rect(w, h)` takes half-sizes and is centred" },
    Guess { word: "translate", replacement: Some("at"), hint: PLACE },
    Guess { word: "translation", replacement: Some("at"), hint: PLACE },
];

/// The advice for `word`, if it is a word other tools use.
pub fn guess(word: &str) -> Option<&'static Guess> {
    GUESSES.iter().find(|g| g.word == word)
}

/// Advice for a transform written before its shape, as OpenSCAD writes it
/// (`rotate([0, 45, 0]) box(1)`): scnc's transforms follow the shape.
pub fn postfix_hint(keyword: &str) -> String {
    let example = match keyword {
        "rotate" => "box(1) rotate [0, 45, 0]",
        "scale" => "box(1) scale 2",
        "at" => "box(1) at [0, 1, 0]",
        _ => "box(1) with material(color = #ff0000)",
    };
    format!("in scnc `{keyword}` follows the shape it applies to: `{example}`")
}
