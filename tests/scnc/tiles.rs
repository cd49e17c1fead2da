//! Parts of an image (`render --tile`, `--region`) and `scnc merge`: merged parts are
//! the whole render byte for byte, and bad parts or part specifications are refused
//! without writing anything.

use crate::support::{ok, path, refused, scnc};

/// A size whose rows and columns are not multiples of the 4×4 blocks rays go in.
const SIZE: [&str; 4] = ["--width", "97", "--height", "61"];

/// The bytes of `scene` rendered with `args` as `n` tiles (`--tile I/N`) in `dir` and
/// merged by `scnc merge`.
fn tiles_merged(dir: &std::path::Path, scene: &str, args: &[&str], n: u32) -> Vec<u8> {
    let parts: Vec<String> = (0..n)
        .map(|i| {
            let part = dir.join(format!("part-{i}.png"));
            let tile = format!("{i}/{n}");
            ok(&scnc(&[&["render", scene, "-o", path(&part), "--tile", &tile][..], args].concat()));
            path(&part).to_string()
        })
        .collect();
    let merged = dir.join("merged.png");
    let mut merge = vec!["merge"];
    merge.extend(parts.iter().map(String::as_str));
    merge.extend(["-o", path(&merged)]);
    ok(&scnc(&merge));
    std::fs::read(&merged).expect("merged")
}

#[test]
fn merged_tiles_are_the_whole_render_byte_for_byte() {
    let dir = tempfile::tempdir().expect("tempdir");
    for (scene, extra) in
        [("examples/seed/06-many-spheres.scn", &[][..]), ("examples/features/union.scn", &["--geometry", "mesh"][..])]
    {
        let full = dir.path().join("full.png");
        ok(&scnc(&[&["render", scene, "-o", path(&full)][..], &SIZE, extra].concat()));
        let args = [&SIZE[..], extra].concat();
        for n in [1u32, 3, 7] {
            let same = tiles_merged(dir.path(), scene, &args, n) == std::fs::read(&full).expect("full");
            assert!(same, "{scene}: {n} tiles merged differ from the whole render");
        }
    }
}

/// Light transport splats a sample into its neighbours' pixels too, so a part is traced
/// with a border: tiles across the film's strips of rows (of 8), merged, and a region
/// are still the whole render's pixels byte for byte.
#[test]
fn light_transport_parts_are_the_whole_render() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scene = "examples/light/cornell.scn";
    let size = ["--width", "23", "--height", "37", "--samples", "4"];
    let full = dir.path().join("full.png");
    ok(&scnc(&[&["render", scene, "-o", path(&full)][..], &size].concat()));
    for n in [2u32, 5] {
        let same = tiles_merged(dir.path(), scene, &size, n) == std::fs::read(&full).expect("full");
        assert!(same, "{n} tiles of light transport merged differ from the whole render");
    }
    let part = dir.path().join("part.png");
    ok(&scnc(&[&["render", scene, "-o", path(&part), "--region", "1,15,22,18"][..], &size].concat()));
    let full = image::open(&full).expect("full").to_rgb8();
    let part = image::open(&part).expect("part").to_rgba8();
    for (x, y, p) in part.enumerate_pixels() {
        if (1..22).contains(&x) && (15..18).contains(&y) {
            assert_eq!(p.0[..3], full.get_pixel(x, y).0, "({x}, {y})");
        }
    }
}

/// A region cut across the 4×4 blocks has exactly the whole render's pixels there and
/// is transparent elsewhere.
#[test]
fn a_region_is_the_whole_render_cropped() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scene = "examples/seed/05-mirrors.scn";
    let (full, part) = (dir.path().join("full.png"), dir.path().join("part.png"));
    ok(&scnc(&[&["render", scene, "-o", path(&full)][..], &SIZE].concat()));
    ok(&scnc(&[&["render", scene, "-o", path(&part), "--region", "5,7,33,29"][..], &SIZE].concat()));
    let full = image::open(&full).expect("full").to_rgb8();
    let part = image::open(&part).expect("part").to_rgba8();
    assert_eq!(part.dimensions(), full.dimensions());
    for (x, y, p) in part.enumerate_pixels() {
        let inside = (5..33).contains(&x) && (7..29).contains(&y);
        if inside {
            assert_eq!(p.0, [full.get_pixel(x, y).0[0], full.get_pixel(x, y).0[1], full.get_pixel(x, y).0[2], 255]);
        } else {
            assert_eq!(p.0, [0, 0, 0, 0], "({x}, {y}) outside the region");
        }
    }
}

#[test]
fn bad_parts_are_refused_and_nothing_is_written() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scene = "examples/seed/01-sphere.scn";
    let part = |name: &str, args: &[&str]| {
        let p = dir.path().join(name);
        ok(&scnc(&[&["render", scene, "-o", path(&p)][..], args].concat()));
        path(&p).to_string()
    };
    let (a, b) = (
        part("a.png", &[&SIZE[..], &["--tile", "0/2"]].concat()),
        part("b.png", &[&SIZE[..], &["--tile", "1/2"]].concat()),
    );
    let small = part("small.png", &["--width", "40", "--height", "30", "--tile", "1/2"]);
    let whole = part("whole.png", &SIZE);
    let out = dir.path().join("out.png");
    for (parts, message) in [
        // The part an overlap is with is found again among the earlier ones.
        (vec![&b, &a, &a], format!("`{a}` and `{a}` both cover pixel (0, 0)")),
        (vec![&a], "pixels are in no part, the first at (0, 30)".into()),
        (vec![&a, &small], "parts of one image have its size".into()),
        (vec![&whole], "is not a part".into()),
    ] {
        let mut args = vec!["merge"];
        args.extend(parts.iter().map(|p| p.as_str()));
        args.extend(["-o", path(&out)]);
        let run = scnc(&args);
        let err = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(1), "{err}");
        assert!(err.contains(&message), "expected `{message}` in: {err}");
        assert!(!out.exists(), "a failed merge wrote {}", out.display());
    }
    for (flag, value, message) in [
        ("--tile", "2/2", "bands are numbered 0 to N − 1"),
        ("--tile", "0/0", "bands are numbered 0 to N − 1"),
        ("--tile", "x", "expected I/N"),
        ("--tile", "0/62", "62 bands of rows in an image 61 rows high"),
        ("--region", "1,2,3", "four numbers"),
        ("--region", "5,5,5,9", "is empty"),
        ("--region", "0,0,98,10", "outside the 97×61 image"),
    ] {
        let run = scnc(&[&["render", scene, "-o", path(&out), flag, value][..], &SIZE].concat());
        let err = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(2), "{flag} {value}: {err}");
        assert!(err.contains(message), "{flag} {value}: expected `{message}` in: {err}");
        assert!(!out.exists());
    }
}

/// `--bit-depth 16` writes a 16-bit PNG, its parts merge into the same 16-bit image byte
/// for byte, and parts of different depths, or a depth PNG has not, are refused.
#[test]
fn sixteen_bit_renders_and_parts() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scene = "examples/features/patterns.scn";
    let full = dir.path().join("full.png");
    ok(&scnc(&[&["render", scene, "-o", path(&full), "--bit-depth", "16"][..], &SIZE].concat()));
    let decoded = image::open(&full).expect("a PNG");
    assert!(matches!(decoded, image::DynamicImage::ImageRgb16(_)), "{:?}", decoded.color());
    let parts: Vec<String> = (0..2)
        .map(|i| {
            let part = dir.path().join(format!("part-{i}.png"));
            let tile = format!("{i}/2");
            ok(&scnc(
                &[&["render", scene, "-o", path(&part), "--tile", &tile, "--bit-depth", "16"][..], &SIZE].concat(),
            ));
            path(&part).to_string()
        })
        .collect();
    let merged = dir.path().join("merged.png");
    ok(&scnc(&["merge", &parts[0], &parts[1], "-o", path(&merged)]));
    let (a, b) = (image::open(&full).expect("full"), image::open(&merged).expect("merged"));
    assert!(a.as_bytes() == b.as_bytes() && a.color() == b.color(), "merged 16-bit parts differ from the render");
    // An 8-bit part beside a 16-bit one.
    let eight = dir.path().join("eight.png");
    ok(&scnc(&[&["render", scene, "-o", path(&eight), "--tile", "1/2"][..], &SIZE].concat()));
    let mixed = dir.path().join("mixed.png");
    refused(&scnc(&["merge", &parts[0], path(&eight), "-o", path(&mixed)]), 1, "bits per channel");
    assert!(!mixed.exists());
    refused(&scnc(&["render", scene, "-o", path(&dir.path().join("x.png")), "--bit-depth", "12"]), 2, "8 or 16");
}

/// The largest 16-bit image `render` writes (8200×8200, within its 100-million-pixel
/// limit) merges from two parts under a 1 GB address-space cap: the parts are read a
/// row at a time into the image (403 MB as RGB), where reading each whole (538 MB as
/// RGBA, then copied) needed 1.75 GB. The parts are written here, row by row, as
/// `render --tile` writes them: the top band opaque in one, the rest in the other.
#[cfg(unix)]
#[test]
fn the_largest_sixteen_bit_parts_merge_in_bounded_memory() {
    let dir = tempfile::tempdir().expect("tempdir");
    let side = 8200usize;
    for (name, band) in [("top.png", 0..3000), ("bottom.png", 3000..side)] {
        let file = std::io::BufWriter::new(std::fs::File::create(dir.path().join(name)).expect("a part"));
        let mut encoder = png::Encoder::new(file, side as u32, side as u32);
        encoder.set_color(png::ColorType::Rgba);
        encoder.set_depth(png::BitDepth::Sixteen);
        encoder.set_compression(png::Compression::Fastest);
        let mut writer = encoder.write_header().expect("header");
        let mut stream = writer.stream_writer().expect("stream");
        let (opaque, clear) = ([0x12u8, 0x34, 0x56, 0x78, 0x9a, 0xbc, 0xff, 0xff].repeat(side), vec![0u8; side * 8]);
        for y in 0..side {
            std::io::Write::write_all(&mut stream, if band.contains(&y) { &opaque } else { &clear }).expect("a row");
        }
        stream.finish().expect("the part");
    }
    let run = crate::support::scnc_capped(1_000_000, dir.path(), &["merge", "top.png", "bottom.png", "-o", "all.png"]);
    ok(&run);
    let mut reader =
        png::Decoder::new(std::io::BufReader::new(std::fs::File::open(dir.path().join("all.png")).expect("merged")))
            .read_info()
            .expect("a PNG");
    let info = reader.info();
    assert_eq!(
        (info.width, info.height, info.color_type, info.bit_depth),
        (8200, 8200, png::ColorType::Rgb, png::BitDepth::Sixteen)
    );
    let expected = [0x12u8, 0x34, 0x56, 0x78, 0x9a, 0xbc].repeat(side);
    let mut rows = 0;
    while let Some(row) = reader.next_row().expect("a row") {
        assert!(row.data() == expected.as_slice(), "row {rows} differs");
        rows += 1;
    }
    assert_eq!(rows, side);
}
