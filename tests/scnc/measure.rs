//! `scnc measure`: proved intervals that hold the exact figures, the mesh's estimates
//! beside them, and the JSON tools read.

use crate::support::{check_golden, finish, scnc};

/// Every library body of `benches/nine` has its exact volume (`exact.json`) inside the
/// interval proved from its distance bound, and its mesh's volume within 0.2 % of it.
#[test]
fn exact_volumes_lie_in_their_proved_intervals() {
    let exact: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string("benches/nine/exact.json").unwrap()).unwrap();
    let mut failures = Vec::new();
    for (body, v) in exact.as_object().unwrap() {
        let v = v.as_f64().unwrap();
        let file = format!("benches/nine/{body}.scn");
        let out = scnc(&["measure", &file, "--cells", "400000", "--message-format", "json"]);
        assert!(out.status.success(), "{body}: {}", String::from_utf8_lossy(&out.stderr));
        let line = String::from_utf8_lossy(&out.stdout).lines().next().unwrap_or("").to_string();
        let m: serde_json::Value = serde_json::from_str(&line).unwrap();
        let proved = &m["proved"]["volume"];
        let (lo, hi) = (proved[0].as_f64().unwrap(), proved[1].as_f64().unwrap());
        if !(lo <= v && v <= hi) {
            failures.push(format!("{body}: exact volume {v} outside the proved [{lo}, {hi}]"));
        }
        if hi - lo > 0.5 * v {
            failures.push(format!("{body}: the interval [{lo}, {hi}] says next to nothing"));
        }
        let mesh = m["mesh"]["volume"].as_f64().unwrap();
        if ((mesh - v) / v).abs() > 2e-3 {
            failures.push(format!("{body}: the mesh's volume {mesh} is {:.3} % off", 100.0 * (mesh - v) / v));
        }
    }
    finish(failures);
}

/// The JSON, one object per line in scene order and then the total, is held to a
/// golden; a mesh object has only mesh figures, and a tighter tolerance costs cells.
#[test]
fn measure_json_golden() {
    let args = ["measure", "tests/data/measure/parts.scn", "--cells", "200000", "--message-format", "json"];
    let out = scnc(&args);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    let lines: Vec<serde_json::Value> = text.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    let names: Vec<&str> = lines.iter().map(|l| l["object"].as_str().unwrap()).collect();
    assert_eq!(names, ["sphere", "box", "box_2", "total"]);
    assert!(lines[2]["proved"].is_null() && lines[2]["mesh"]["volume"].as_f64().unwrap() > 0.99);
    assert!(lines[3]["proved"].is_null(), "a total with a mesh object is the meshes' sum only");
    let mut failures = Vec::new();
    failures.extend(check_golden(std::path::Path::new("tests/data/measure/parts.json"), &text));
    let width = |args: &[&str]| {
        let out = scnc(args);
        let first: serde_json::Value =
            serde_json::from_str(String::from_utf8_lossy(&out.stdout).lines().next().unwrap()).unwrap();
        let v = &first["proved"]["volume"];
        (v[1].as_f64().unwrap() - v[0].as_f64().unwrap(), first["proved"]["cells"].as_u64().unwrap())
    };
    let (coarse, few) = width(&["measure", "benches/nine/cone.scn", "--tolerance", "5%", "--message-format", "json"]);
    let (fine, many) = width(&["measure", "benches/nine/cone.scn", "--tolerance", "2%", "--message-format", "json"]);
    assert!(fine < coarse && many > few, "5 %: {coarse} in {few} cells; 2 %: {fine} in {many}");
    finish(failures);
}

/// Bad input is refused with a clear message: a tolerance out of range, and a scene
/// with nothing to measure.
#[test]
fn measure_refuses_what_it_cannot_measure() {
    let out = scnc(&["measure", "benches/nine/cone.scn", "--tolerance", "150%"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("not a relative tolerance"));
    let dir = tempfile::tempdir().unwrap();
    let empty = dir.path().join("empty.scn");
    std::fs::write(&empty, "light ambient(1)\n").unwrap();
    let out = scnc(&["measure", empty.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no objects to measure"));
}

/// A material's density weighs the mass and the inertia: a 2-unit cube of density 7.8
/// has mass 62.4 and inertia 62.4·(2² + 2²)/12 about each axis, inside the proved
/// intervals and exact on its mesh; two objects of different densities are not proved
/// as one, and their mesh total weighs each by its own; an object whose parts have
/// different densities is flagged, and so is a total that holds it.
#[test]
fn densities_weigh_mass_and_inertia() {
    let measured = |text: &str| -> Vec<serde_json::Value> {
        let dir = crate::support::files(&[("d.scn", text.as_bytes())]);
        let scene = dir.path().join("d.scn");
        let out = scnc(&["measure", crate::support::path(&scene), "--cells", "400000", "--message-format", "json"]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        String::from_utf8_lossy(&out.stdout).lines().map(|l| serde_json::from_str(l).unwrap()).collect()
    };
    let lines = measured("object box(1) with material(density = 7.8)\nobject sphere(1) at [3, 0, 0]\n");
    let (cube, sphere, total) = (&lines[0], &lines[1], &lines[2]);
    assert_eq!(cube["density"].as_f64(), Some(7.8));
    let mass = &cube["proved"]["mass"];
    assert!(mass[0].as_f64().unwrap() <= 62.4 && 62.4 <= mass[1].as_f64().unwrap(), "{mass}");
    assert!((cube["mesh"]["mass"].as_f64().unwrap() - 62.4).abs() < 1e-9);
    assert!((cube["mesh"]["inertia"][0][0].as_f64().unwrap() - 41.6).abs() < 1e-9);
    let ixx = &cube["proved"]["inertia"][0][0];
    assert!(ixx[0].as_f64().unwrap() <= 41.6 && 41.6 <= ixx[1].as_f64().unwrap(), "{ixx}");
    assert_eq!(sphere["density"].as_f64(), Some(1.0));
    assert!(total["proved"].is_null() && total["density"].is_null());
    let m_sphere = sphere["mesh"]["mass"].as_f64().unwrap();
    let want_x = (m_sphere * 3.0) / (62.4 + m_sphere);
    let got_x = total["mesh"]["centre_of_mass"][0].as_f64().unwrap();
    assert!((got_x - want_x).abs() < 1e-6, "{got_x} not {want_x}");
    assert!((total["mesh"]["mass"].as_f64().unwrap() - 62.4 - m_sphere).abs() < 1e-9);

    let lines = measured(
        "object union(box(0.5) with material(density = 2), sphere(0.5) at [0, 3, 0])\nobject sphere(1) at [3, 0, 0]\n",
    );
    assert!(lines[0]["density"].is_null(), "parts of densities 2 and 1");
    assert!(lines[2]["proved"].is_null() && lines[2]["mesh"].is_null());
}
