//! Scene errors: every check made after parsing is positioned where the parser read the
//! value (not where its text first occurs), and every message is one line.

use std::path::Path;

use cov_render::World;

const BASE: &str = r#"Scene(
    camera: (position: (0.0, 1.0, 3.0), look_at: LOOK, fov: FOV, width: 8, height: 8LENS),
    materials: { "w": Diffuse(albedo: (0.5, 0.5, 0.5)), MAT },
    lights: LIGHTS,
    shapes: [Sphere(center: (0.0, 0.5, 0.0), radius: 0.5, material: "w"), SHAPE],
)"#;

/// The scene text with each `(placeholder, value)` replaced (defaults for the others).
fn scene(parts: &[(&str, &str)]) -> String {
    let mut t = BASE.to_string();
    for (k, v) in parts {
        t = t.replace(k, v);
    }
    scene_from(&t)
}

/// `text` (a [`BASE`] with some placeholders replaced) with defaults for the others.
fn scene_from(text: &str) -> String {
    let mut t = text.to_string();
    for (k, v) in [
        ("LOOK", "(0.0, 1.0, 0.0)"),
        ("FOV", "40.0"),
        ("LENS", ""),
        (", MAT", ""),
        (
            "LIGHTS",
            "[Sphere(center: (0.0, 2.0, 0.0), radius: 0.2, radiance: (1.0, 1.0, 1.0))]",
        ),
        (", SHAPE", ""),
    ] {
        t = t.replace(k, v);
    }
    t
}

/// The error of `text`, as `line:col: message`.
fn error(text: &str) -> String {
    let e = World::from_text(text, "s.ron", Path::new("."))
        .unwrap_err()
        .to_string();
    assert_eq!(e.lines().count(), 1, "{e}");
    e.strip_prefix("s.ron:").unwrap_or(&e).to_string()
}

#[test]
fn checks_after_parsing_point_at_the_value() {
    let cases: [(&[(&str, &str)], &str); 15] = [
        (
            &[("LOOK", "(0.0, 1.0, 3.0)")],
            "2:50: the camera looks at its own position",
        ),
        // Beyond the scene's extent: normalising the view direction overflowed, and the
        // message blamed `up`.
        (
            &[("LOOK", "(0.0, 0.9, -1e200)")],
            "2:50: `look_at` must lie within ±1e12 m of the origin",
        ),
        // Beyond it by the camera's own position: it used to be read as looking straight
        // up (the view direction overflowed), at `look_at`.
        (
            &[("(position: (0.0, 1.0, 3.0)", "(position: (0.0, 1e308, 3.0)")],
            "2:24: `position` must lie within ±1e12 m of the origin",
        ),
        // Squared in the lens equation: past 1e154 it overflowed into a black image.
        (
            &[("LENS", ", lens: (aperture: 0.01, focus_distance: 1e155)")],
            "2:138: focus_distance must be at most 1e12 m (the scene's extent), got 1e155",
        ),
        (
            &[("FOV", "180.0")],
            "2:72: fov must be 1e-6 to below 180 degrees, got 180",
        ),
        (
            &[("LENS", ", lens: (aperture: 0.01, focus_distance: 0.01)")],
            "2:138: focus_distance 0.01 must exceed the focal length 0.05",
        ),
        (
            &[("LENS", ", shutter: (open: 0.5, close: 0.1)")],
            "2:127: the shutter closes (0.1) before it opens (0.5)",
        ),
        (
            &[("LENS", ", shutter: (open: 0.25, close: 0.25)")],
            "2:128: the shutter must stay open 1e-15 to",
        ),
        (
            &[("MAT", r#""hot": Diffuse(albedo: (2.0, 0.5, 0.5))"#)],
            "3:80: material `hot`: an albedo above 1",
        ),
        // Lobes narrower than f64 resolves directions lost their reflections unsaid.
        (
            &[("MAT", r#""glass": Ggx(albedo: (0.5, 0.5, 0.5), alpha: 1e-10)"#)],
            "3:102: material `glass`: `alpha` = 1e-10 is below 1e-6, a lobe narrower than f64 resolves",
        ),
        (
            &[(
                "MAT",
                r#""glass": Phong(albedo: (0.5, 0.5, 0.5), exponent: 1e20)"#,
            )],
            "3:107: material `glass`: `exponent` = 1e20 is above 1e12, a lobe narrower",
        ),
        (&[("LIGHTS", "[]")], "4:13: the scene has no light"),
        (
            &[(
                "LIGHTS",
                "[Rect(corner: (0.0, 2.0, 0.0), edge_u: (1.0, 0.0, 0.0), edge_v: (2.0, 0.0, 0.0), radiance: (1.0, 1.0, 1.0))]",
            )],
            "4:52: a Rect light's `edge_u` and `edge_v` span no area",
        ),
        (
            &[(
                "SHAPE",
                r#"Quad(corner: (0.0, 0.0, 0.0), edge_u: (0.0, 0.0, 0.0), edge_v: (1.0, 0.0, 0.0), material: "w")"#,
            )],
            "5:113: a Quad's `edge_u` and `edge_v` span no area",
        ),
        // The second shape names a material that the first one's text also contains
        // (`"w"` inside `"white"`): the position is the second shape's own.
        (
            &[(
                "SHAPE",
                r#"Sphere(center: (0.0, 0.5, 0.0), radius: 0.5, material: "white")"#,
            )],
            "5:130: unknown material `white`; the scene defines: w",
        ),
    ];
    for (parts, want) in cases {
        let e = error(&scene(parts));
        assert!(e.starts_with(want), "expected `{want}`, got `{e}`");
    }
}

/// A value written on the line after its field, after a comment, is found where it is.
#[test]
fn a_value_on_its_own_line_is_found_there() {
    let text = scene(&[(
        "SHAPE",
        "Sphere(center: (0.0, 0.5, 0.0), radius: 0.5, material: // which\n        \"gold\")",
    )]);
    assert!(
        error(&text).starts_with("6:9: unknown material `gold`"),
        "{}",
        error(&text)
    );
}

/// Names with line breaks and other control characters are echoed escaped, in one line.
#[test]
fn names_with_control_characters_stay_on_one_line() {
    let text = scene(&[(
        "SHAPE",
        "Sphere(center: (0.0, 0.5, 0.0), radius: 0.5, material: \"go\\nld\\u{1b}[31m\")",
    )]);
    let e = error(&text);
    assert!(e.contains(r"unknown material `go\nld\u{1b}[31m`"), "{e}");
    let text = scene(&[("SHAPE", "Mesh(obj: \"no\\nwhere.obj\", material: \"w\")")]);
    let e = error(&text);
    assert!(
        e.contains(r"OBJ `no\nwhere.obj`: no such file: ./no\nwhere.obj"),
        "{e}"
    );
    let text = scene(&[("MAT", "\"h\\tot\": Diffuse(albedo: (2.0, 0.5, 0.5))")]);
    assert!(error(&text).contains(r"material `h\tot`"), "{}", error(&text));
    // An unknown field whose name the parser echoes.
    let text = scene(&[("FOV", "40.0, \"x\\ny\": 1")]);
    assert_eq!(error(&text).lines().count(), 1);
}

/// Mutated bundled scenes never panic: each loads, or fails with one line positioned in
/// the file.
#[test]
fn mutated_scenes_give_one_positioned_line() {
    use rand::{Rng, SeedableRng};
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes");
    let files: Vec<String> = ["cornell.ron", "pool.ron", "glossy.ron"]
        .iter()
        .map(|f| std::fs::read_to_string(dir.join(f)).expect("bundled scene"))
        .collect();
    let alphabet: Vec<char> = "\n\t \"\\(),:[]{}0123456789.-eEabcxyz\u{1b}\u{0}é"
        .chars()
        .collect();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    for case in 0..600 {
        let mut text: Vec<char> = files[case % files.len()].chars().collect();
        for _ in 0..rng.random_range(1..5) {
            let p = rng.random_range(0..=text.len());
            let c = alphabet[rng.random_range(0..alphabet.len())];
            match rng.random_range(0..3) {
                0 if p < text.len() => {
                    text.remove(p);
                }
                1 => text.insert(p, c),
                _ if p < text.len() => text[p] = c,
                _ => text.push(c),
            }
        }
        let text: String = text.into_iter().collect();
        if let Err(e) = World::from_text(&text, "m.ron", &dir) {
            let s = e.to_string();
            assert_eq!(s.lines().count(), 1, "case {case}: {s}\n{text}");
            assert!(e.at.is_some(), "case {case}: not positioned: {s}");
        }
    }
}

/// A value the parser refuses is named by its field, as the user wrote it.
#[test]
fn refused_values_name_their_field() {
    let radius = scene(&[(
        "SHAPE",
        r#"Sphere(center: (0.0, 0.5, 0.0), radius: -0.1, material: "w")"#,
    )]);
    let e = error(&radius);
    assert!(
        e.starts_with("5:115: `radius` must be finite and > 0, got -0.1"),
        "{e}"
    );
    let center = scene(&[(
        "SHAPE",
        r#"Sphere(center: (0.0, inf, 0.0), radius: 0.5, material: "w")"#,
    )]);
    let e = error(&center);
    assert!(e.contains("`center`: a vector must be finite"), "{e}");
    let fov = scene(&[("FOV", "-1.0")]);
    assert!(error(&fov).contains("`fov`"), "{}", error(&fov));
    // A pair's entry has no field name of its own: the pair is named.
    let repeat = scene(&[]).replace(
        "    materials:",
        "    textures: { \"t\": Checker(checks: (2, 2), a: (1.0, 1.0, 1.0), b: (0.0, 0.0, 0.0), repeat: (1.0, NaN)) },\n    materials:",
    );
    let e = error(&repeat);
    assert!(
        e.contains("`repeat`: each entry must be finite and > 0, got (1, NaN)"),
        "{e}"
    );
}

/// What single precision cannot hold is refused where it is written (a sphere or a
/// sphere light at its centre): a shape or a light past `MAX_COORD` (at rest or by its motion over the shutter), a colour past
/// `MAX_COLOUR` (printed compactly); and a frame that moves a shape past it is an error,
/// not a broken BVH.
#[test]
fn what_single_precision_cannot_hold_is_refused() {
    let far = scene(&[(
        "SHAPE",
        r#"Sphere(center: (2e12, 0.5, 0.0), radius: 0.5, material: "w")"#,
    )]);
    let e = error(&far);
    assert!(e.starts_with("5:90: this sphere reaches 2e12 m"), "{e}");
    let light = scene(&[(
        "LIGHTS",
        "[Sphere(center: (0.0, 2.0, -5e12), radius: 0.2, radiance: (1.0, 1.0, 1.0))]",
    )]);
    assert!(
        error(&light).starts_with("4:29: this light reaches 5e12 m"),
        "{}",
        error(&light)
    );
    let fast = scene(&[
        ("LENS", ", shutter: (open: 0.0, close: 0.5)"),
        (
            "SHAPE",
            r#"Sphere(center: (0.0, 0.5, 0.0), radius: 0.5, material: "w", velocity: (0.0, 1e300, 0.0))"#,
        ),
    ]);
    assert!(error(&fast).contains("reaches 5e299 m"), "{}", error(&fast));
    // Below what the tracer's offsets and f64 resolve at that scale: refused at the size.
    for (part, at, what) in [
        (
            (
                "LIGHTS",
                "[Sphere(center: (0.0, 2.0, 0.0), radius: 1e-100, radiance: (1.0, 1.0, 1.0))]",
            ),
            "4:54",
            "this sphere's radius is 1e-100 m; at least 3e-6 m here",
        ),
        (
            (
                "SHAPE",
                r#"Sphere(center: (3.0, 0.5, 0.0), radius: 3.9e-6, material: "w")"#,
            ),
            "5:115",
            "this sphere's radius is 3.9e-6 m; at least 4e-6 m here",
        ),
        (
            (
                "SHAPE",
                r#"Quad(corner: (0.0, 0.0, 0.0), edge_u: (1e-9, 0.0, 0.0), edge_v: (0.0, 0.0, 1.0), material: "w")"#,
            ),
            "5:113",
            "this Quad's edge is 1e-9 m; at least 1e-6 m here",
        ),
        (
            ("FOV", "1e-300"),
            "2:72",
            "fov must be 1e-6 to below 180 degrees, got 1e-300",
        ),
        (
            ("LENS", ", lens: (aperture: 1e-155, focus_distance: 4.0)"),
            "2:116",
            "aperture (0 for a pinhole) must be 1e-9 to 1e6 m, got 1e-155",
        ),
        (
            (
                "LENS",
                ", lens: (aperture: 0.01, focus_distance: 4.0, focal_length: 1e-300)",
            ),
            "2:157",
            "focal_length must be 1e-9 to 1e6 m, got 1e-300",
        ),
        (
            ("LENS", ", up: (0.0, 0.0, 0.0)"),
            "2:103",
            "`up` is the zero vector",
        ),
        (
            ("LENS", ", shutter: (open: 0.0, close: 1e-160)"),
            "2:127",
            "the shutter must stay open 1e-15 to 1e6 s (close − open), got 1e-160",
        ),
    ] {
        let e = error(&scene(&[part]));
        assert!(e.starts_with(&format!("{at}: {what}")), "{e}");
    }
    let hot = scene(&[(
        "LIGHTS",
        "[Sphere(center: (0.0, 2.0, 0.0), radius: 0.2, radiance: (1e300, 1.0, 1.0))]",
    )]);
    assert!(
        error(&hot).contains("`radiance`: a colour must be finite, ≥ 0 and ≤ 1e9, got (1e300, 1, 1)"),
        "{}",
        error(&hot)
    );
    // At rest within reach, moving out of it by frame 1000 (at 24 frames per second).
    let drifting = scene(&[
        ("LENS", ", shutter: (open: 0.0, close: 0.01)"),
        (
            "SHAPE",
            r#"Sphere(center: (0.0, 0.5, 0.0), radius: 0.5, material: "w", velocity: (1e11, 0.0, 0.0))"#,
        ),
    ]);
    let world = || World::from_text(&drifting, "s.ron", Path::new(".")).expect("within reach at frame 0");
    assert!(world().at_frame(1).is_ok());
    let e = world().at_frame(1000).unwrap_err().to_string();
    assert!(
        e.contains("every shape and the camera stay within ±1e12 m"),
        "{e}"
    );
    // The camera too: far by its motion over the shutter (where the velocity is), and by
    // a frame of its drift.
    let flying = scene(&[(
        "LENS",
        ", shutter: (open: 0.0, close: 0.1), velocity: (1e300, 0.0, 0.0)",
    )]);
    let e = error(&flying);
    assert!(
        e.starts_with("2:143: the camera reaches 1e299 m from the origin"),
        "{e}"
    );
    let drifting = scene(&[(
        "LENS",
        ", shutter: (open: 0.0, close: 0.01), velocity: (1e11, 0.0, 0.0)",
    )]);
    let world = || World::from_text(&drifting, "s.ron", Path::new(".")).expect("within reach at frame 0");
    assert!(world().at_frame(1).is_ok());
    let e = world().at_frame(1000).unwrap_err().to_string();
    assert!(
        e.contains("every shape and the camera stay within ±1e12 m"),
        "{e}"
    );
}

/// A material or texture name given twice is an error at the second name, with the
/// first's place, not a silent replacement of the first.
#[test]
fn a_name_defined_twice_is_refused() {
    let twice = scene(&[("MAT", r#""w": Diffuse(albedo: (0.9, 0.1, 0.1))"#)]);
    let e = error(&twice);
    assert!(e.starts_with("3:57: `w` is defined twice (first at 3:18)"), "{e}");
    let textures = BASE.replace(
        "    materials:",
        "    textures: { \"t\": Checker(checks: (2, 2), a: (1.0, 1.0, 1.0), b: (0.0, 0.0, 0.0)), \"t\": Stripes(count: 2, duty: 0.5, a: (1.0, 1.0, 1.0), b: (0.0, 0.0, 0.0)) },\n    materials:",
    );
    let e = error(&scene_from(&textures));
    assert!(e.contains("`t` is defined twice"), "{e}");
}

/// A texture or mesh path that is there but not a file (a directory) says so, rather
/// than that there is no such file.
#[test]
fn a_path_that_is_not_a_file_says_so() {
    let dir = BASE.replace(
        "    materials:",
        "    textures: { \"t\": Image(file: \".\") },\n    materials:",
    );
    let e = error(&scene_from(&dir));
    assert!(e.contains("texture `t`: not a regular file: ./."), "{e}");
    let mesh = scene(&[("SHAPE", r#"Mesh(obj: ".", material: "w")"#)]);
    assert!(error(&mesh).contains("not a regular file"), "{}", error(&mesh));
    let missing = scene(&[("SHAPE", r#"Mesh(obj: "missing.obj", material: "w")"#)]);
    assert!(error(&missing).contains("no such file"), "{}", error(&missing));
    // A loop of links is there, but no file: the system's reason, not "no such file".
    #[cfg(unix)]
    {
        let dir = std::env::temp_dir().join(format!("covtrace-loop-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (a, b) = (dir.join("a.obj"), dir.join("b.obj"));
        let _ = (std::fs::remove_file(&a), std::fs::remove_file(&b));
        std::os::unix::fs::symlink(&b, &a).unwrap();
        std::os::unix::fs::symlink(&a, &b).unwrap();
        let looped = scene(&[(
            "SHAPE",
            &format!(r#"Mesh(obj: "{}", material: "w")"#, a.display()),
        )]);
        let e = error(&looped);
        assert!(!e.contains("no such file") && e.contains("symbolic links"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

/// What a few bytes of input must not make the loader do: read a device without end,
/// follow an OBJ's `mtllib` (to a device or a pipe), or make textures of tens of
/// gigabytes. Each is refused, or ignored for `mtllib`, at once.
#[test]
fn small_inputs_cannot_ask_for_unbounded_work() {
    // A scene read from a device: cut at the bound, one line.
    let e = World::load(Path::new("/dev/zero")).unwrap_err().to_string();
    assert!(
        e.contains("more than 16777216 bytes; scene files are read up to that"),
        "{e}"
    );
    // An OBJ naming a material library on a device: the mesh loads, the library is not read.
    let dir = std::env::temp_dir().join(format!("covtrace-scene-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    std::fs::write(
        dir.join("tri.obj"),
        "mtllib /dev/zero\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl x\nf 1 2 3\n",
    )
    .expect("write");
    let text = scene(&[("SHAPE", r#"Mesh(obj: "tri.obj", material: "w")"#)]);
    let world = World::from_text(&text, "s.ron", &dir).expect("the mesh loads");
    assert!(world.geometry.len() >= 2, "{}", world.geometry.len());
    // Three procedural textures of 4096² (2 GB with their pyramids): refused at the third
    // before any is made.
    let big = BASE.replace(
        "    materials:",
        &format!(
            "    textures: {{ {} }},\n    materials:",
            (0..3)
                .map(|i| format!(
                    "\"t{i}\": Checker(checks: (2, 2), a: (1.0, 1.0, 1.0), b: (0.0, 0.0, 0.0), size: 4096)"
                ))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    );
    // A texture's size out of range is said before what depends on it.
    let zero = BASE.replace(
        "    materials:",
        "    textures: { \"t\": Checker(checks: (2, 2), a: (1.0, 1.0, 1.0), b: (0.0, 0.0, 0.0), size: 0) },\n    materials:",
    );
    let e = error(&scene_from(&zero));
    assert!(
        e.contains("texture `t`: size must be 1 to 4096 texels, got 0"),
        "{e}"
    );
    let e = error(&scene_from(&big));
    assert!(
        e.contains(
            "texture `t2` would bring the scene's textures to 50331648 texels; a scene holds at most 33554432"
        ),
        "{e}"
    );
}

/// An error about a value points at the value's first character, whatever ron's own
/// position: after a sign, inside a number, or at the blank before a string.
#[test]
fn a_wrong_value_is_pointed_at_where_it_starts() {
    // `camera: (position: (0.0, 1.0, 3.0), look_at: LOOK, fov: FOV, …`: LOOK's value is
    // written from column 50 of line 2, FOV's from column 72.
    let unclosed = "Sphere(center: (1.0, 0.5, 0.0), radius: 0.5, material: \"w\",\n        \
                    Sphere(center: (2.0, 0.5, 0.0), radius: 0.5, material: \"w\")";
    for (part, value, want) in [
        ("FOV", "\"wide\"", "2:72: `fov` = \"wide\": expected a number"),
        ("FOV", "-40.0", "2:72: `fov` must be finite and > 0, got -40"),
        ("FOV", "0x28", "2:72: `fov` = 0x28: a hexadecimal number"),
        ("FOV", "   true", "2:75: `fov` = true: expected a number"),
        // A number where parentheses belong: said of the field, at the value.
        (
            "LOOK",
            "0.5",
            "2:50: `look_at` = 0.5: expected values in parentheses",
        ),
        (
            "LENS",
            ", lens: 0.04",
            "2:105: `lens` = 0.04: expected `Lens`'s fields in parentheses",
        ),
        // An entry of a list read as a field, because the one before it is not closed.
        (
            "SHAPE",
            unclosed,
            "6:9: found `Sphere` among `Sphere`'s fields: is the `)` that closes the `Sphere` before it missing?",
        ),
        // A tuple of too few values, at its start; a tuple not closed before the next
        // field.
        (
            "(position: (0.0, 1.0, 3.0)",
            "(position: (0.0, 1.0)",
            "2:24: `position` = (0.0, 1.0): expected 3 values, found 2",
        ),
        (
            "(position: (0.0, 1.0, 3.0)",
            "(position: (0.0, 1.0, 3.0,",
            "2:24: `position` is not closed: a `)` is missing before `look_at` (it opens here)",
        ),
        // A required field left out, and a syntax error at the token, not the blank.
        (
            "fov: FOV, ",
            "",
            "2:86: `fov` is missing from `Camera`: it has no default",
        ),
        ("fov: FOV", "fov   = 40.0", "2:73: Expected colon, found `=`"),
        // A field written twice: said in the scene's words, at the second one.
        (
            "FOV",
            "40.0, fov: 30.0",
            "2:78: `fov` is given twice in `Camera`: remove one",
        ),
    ] {
        let e = error(&scene(&[(part, value)]));
        assert!(e.starts_with(want), "{part} = {value}: {e}");
    }
}

/// Values are said as written, at themselves: a decimal below 1 where a whole number
/// belongs is not read as 0, a texture's colour above 1 is pointed at, a number too large
/// for a float is not "inf"; a file of comments alone holds no scene.
#[test]
fn values_are_said_as_written() {
    let e = error(&scene(&[("width: 8", "width: 0.5")]));
    assert!(
        e.starts_with("2:85: `width` = 0.5: expected a whole number, found a decimal number"),
        "{e}"
    );
    // A decimal the parser refuses as a number of its own type is said as before.
    let e = error(&scene(&[("FOV", "0.5, width: 8.5")]).replace(", width: 8, height", ", height"));
    assert!(e.contains("`width` = 8.5: expected a whole number"), "{e}");
    // A texture's colour above 1, at the colour.
    let t = BASE.replace(
        "    materials:",
        "    textures: { \"t\": Checker(checks: (2, 2), a: (1.0, 1.0, 1.0), b: (0.0, 1.5, 0.0)) },\n    materials:",
    );
    let e = error(&scene_from(&t));
    assert!(
        e.starts_with("3:69: texture `t`: colour `b` above 1 reflects more than it receives"),
        "{e}"
    );
    // A number too large for a float is said as written, not as infinity.
    let e = error(&scene(&[("FOV", "1e400")]));
    assert!(
        e.starts_with("2:72: `fov` = 1e400: beyond the largest number a float holds"),
        "{e}"
    );
    let e = error(&scene(&[("FOV", "inf")]));
    assert!(e.contains("`fov` must be finite"), "{e}");
    for text in ["// only a comment\n", "  \n\n", "\u{feff}/* a block */"] {
        let e = error(text);
        assert!(
            e.contains("the file holds no scene: expected `Scene(…)`"),
            "{text:?}: {e}"
        );
    }
}

/// Mistakes in the text's tokens are placed where they are written, not where ron
/// noticed them, and said in the author's words; so are a `)` too many or missing.
#[test]
fn token_mistakes_are_placed_where_they_are_written() {
    let long = format!("{}.0", "9".repeat(400));
    for (parts, want) in [
        // A string's closing quote missing: it ran on to the shape's `"w"`.
        (
            vec![("{ \"w\": Diffuse", "{ \"w: Diffuse")],
            "3:18: this string runs on to line 5: is its closing `\"` missing?".to_string(),
        ),
        (
            vec![("material: \"w\")", "material: \"\\w\")")],
            "5:70: `\\w` is no escape a string knows: write a backslash as `\\\\`".to_string(),
        ),
        (
            vec![("Scene(\n", "Scene(\n    /* not closed\n")],
            "2:5: this block comment is not closed: its `*/` is missing".to_string(),
        ),
        (
            vec![("FOV", "\u{200B}40.0")],
            "2:72: an invisible U+200B character here".to_string(),
        ),
        (
            vec![("LOOK", "(0.0, 0x1, 0.0)")],
            "2:56: `look_at`: value 2 = 0x1: a hexadecimal number".to_string(),
        ),
        (vec![("FOV", "4O.0")], "2:72: `fov` = 4O.0: not a number".to_string()),
        (
            vec![("FOV", long.as_str())],
            "2:72: `fov` = 9999999999999999999999999999999999999999999999999999999999999999… (402 characters): beyond the largest number a float holds".to_string(),
        ),
        (
            vec![("FOV", "40.0)")],
            "2:76: `width` is missing from `Camera`: this `)` closes it before `width` is read; is it one too many?".to_string(),
        ),
        // Pasted characters that look like the syntax's own.
        (
            vec![("{ \"w\": Diffuse", "{ \u{201C}w\u{201D}: Diffuse")],
            "3:18: `\u{201C}` (U+201C) is a typographic quote (it often comes from pasting text): write `\"`".to_string(),
        ),
        (
            vec![("LOOK", "(0.0, \u{2212}1.0, 0.0)")],
            "2:56: `\u{2212}` (U+2212) is a typographic minus sign (it often comes from pasting text): write `-`".to_string(),
        ),
        // Habits of other formats: a `#` comment, a key without quotes, a decimal comma.
        (
            vec![("Scene(\n", "# a comment\nScene(\n")],
            "1:1: `#` does not start a comment: write `//` (or `/* … */`)".to_string(),
        ),
        (
            vec![("{ \"w\": Diffuse", "{ w: Diffuse")],
            "3:18: a name here is written in double quotes: `\"w\"`".to_string(),
        ),
        (
            vec![("radius: 0.5, material: \"w\")", "radius: 0,5, material: \"w\")")],
            "5:54: `radius` = 0,5: a comma ends a value; a decimal number is written with a point (`0.5`)".to_string(),
        ),
        (
            vec![("radius: 0.5, material: \"w\")", "radius: 1,5, material: \"w\")")],
            "5:54: `1,5`: a comma ends a value; a decimal number is written with a point (`1.5`)".to_string(),
        ),
        // A tuple written without blanks is no decimal comma.
        (
            vec![("LOOK", "(0.0,1.0,0.0,2)")],
            "2:63: `look_at` has more than 3 values (found `2`)".to_string(),
        ),
        // A comma left off at a line's end: after the value, not at the next line.
        (
            vec![("fov: FOV, ", "fov: 40.0\n        ")],
            "2:76: a `,` is missing here, before `width` on line 3".to_string(),
        ),
        // Text after the scene, a string never closed, numbers a float cannot hold.
        (
            vec![("SHAPE],\n)", "SHAPE],\n))")],
            "6:2: `)` after the end: the file's value was closed before it".to_string(),
        ),
        (
            vec![("radius: 0.5, material: \"w\")", "radius: 0.5, material: \"w)")],
            "5:69: this string is not closed: its closing `\"` is missing".to_string(),
        ),
        (
            vec![("FOV", "1e-400")],
            "2:72: `fov` = 1e-400: below the smallest number a float holds (about 4.9e-324), read as 0".to_string(),
        ),
        (
            vec![("width: 8", "width: -8")],
            "2:85: `width` = -8: must not be negative".to_string(),
        ),
        (
            vec![(
                "LENS",
                ", lens: (aperture: 0.01, focus_distance: 2.0,\n    shutter: (open: 0.0, close: 0.01)",
            )],
            "3:5: `shutter` is no field of `Lens`: is the `)` that closes `lens` (at 2:99) missing before it?".to_string(),
        ),
    ] {
        let e = error(&scene(&parts));
        assert!(e.starts_with(&want), "{parts:?}: {e}");
    }
    // A light path given where a scene belongs says which command reads it.
    let e = error("// a path\nPath(source: Gaussian(x: 0.3), operators: [])\n");
    assert!(
        e.starts_with("2:1: this file holds a light path (`Path(…)`), and this command reads a scene (`Scene(…)`): trace a path with `covtrace eval`"),
        "{e}"
    );
}

/// A procedural texture's parameter out of range is pointed at where it is written, and
/// named; a parameter left at its default is the texture's, at its name.
#[test]
fn a_texture_parameter_is_pointed_at() {
    // Line 3 is `    textures: { "t": TEXTURE },`: the texture starts at column 22.
    for (texture, want) in [
        (
            "Checker(checks: (0, 2), a: (1.0, 1.0, 1.0), b: (0.0, 0.0, 0.0))",
            "3:38: texture `t`: checks must be 1 to the texture's size (1024) along each side, got (0, 2)",
        ),
        (
            "Checker(checks: (2, 2), a: (1.0, 1.0, 1.0), b: (0.0, 0.0, 0.0), size: 0)",
            "3:92: texture `t`: size must be 1 to 4096 texels, got 0",
        ),
        (
            "Stripes(count: 0, a: (1.0, 1.0, 1.0), b: (0.0, 0.0, 0.0))",
            "3:37: texture `t`: count must be 1 to the texture's size (1024), got 0",
        ),
        (
            "Stripes(count: 4, duty: 1.5, a: (1.0, 1.0, 1.0), b: (0.0, 0.0, 0.0))",
            "3:46: texture `t`: duty must be in (0, 1), got 1.5",
        ),
        (
            "Noise(cells: 16, a: (1.0, 1.0, 1.0), b: (0.0, 0.0, 0.0), size: 8)",
            "3:35: texture `t`: cells must be 1 to the texture's size (8), got 16",
        ),
        (
            "Noise(cells: 4, a: (1.0, 1.0, 1.0), b: (0.0, 0.0, 0.0), size: 5000)",
            "3:84: texture `t`: size must be 1 to 4096 texels, got 5000",
        ),
        (
            "Noise(cells: 4, a: (1.0, 1.0, 1.0), b: (0.0, 0.0, 0.0), repeat: (1.0, 0.0))",
            "3:86: `repeat`: each entry must be finite and > 0, got (1, 0)",
        ),
        // Three of the largest side are more texels than a scene holds: at the third's size.
        (
            "Noise(cells: 4, a: (1.0, 1.0, 1.0), b: (0.0, 0.0, 0.0), size: 4096), \"u\": \
             Stripes(count: 4, a: (1.0, 1.0, 1.0), b: (0.0, 0.0, 0.0), size: 4096), \"v\": \
             Checker(checks: (2, 2), a: (1.0, 1.0, 1.0), b: (0.0, 0.0, 0.0), size: 4096)",
            "3:242: texture `v` would bring the scene's textures to",
        ),
    ] {
        let t = BASE.replace(
            "    materials:",
            &format!("    textures: {{ \"t\": {texture} }},\n    materials:"),
        );
        let e = error(&scene_from(&t));
        assert!(e.starts_with(want), "{texture}: {e}");
    }
}

/// A path's depth is a count the user controls: 1 to 32, refused where it is written,
/// 2 when left out.
#[test]
fn a_path_depth_is_bounded_where_it_is_written() {
    let at = |d: &str| BASE.replace("Scene(\n", &format!("Scene(\n    max_depth: {d},\n"));
    for (d, want) in [
        ("0", "2:16: `max_depth` must be 1 to 32 surface vertices, got 0"),
        ("33", "2:16: `max_depth` must be 1 to 32 surface vertices, got 33"),
        ("-1", "2:16: `max_depth` = -1: must not be negative"),
        ("2.5", "2:16: `max_depth` = 2.5: expected a whole number"),
        (
            "Some(0)",
            "2:16: `max_depth` must be 1 to 32 surface vertices, got 0",
        ),
        ("\"two\"", "2:16: `max_depth` = \"two\": expected a whole number"),
    ] {
        let e = error(&scene_from(&at(d)));
        assert!(e.starts_with(want), "max_depth {d}: {e}");
    }
    let deep = World::from_text(&scene_from(&at("32")), "s.ron", Path::new(".")).expect("32 is allowed");
    assert_eq!(deep.max_depth, 32);
    let plain = World::from_text(&scene(&[]), "s.ron", Path::new(".")).expect("the base scene");
    assert_eq!(plain.max_depth, cov_render::scene::DEFAULT_PATH_DEPTH);
}

/// A camera's rotation rate is bounded where it is written.
#[test]
fn a_camera_turning_too_fast_is_refused_at_its_rate() {
    let e = error(&scene(&[("LENS", ", angular_velocity: (0.0, 1e5, 0.0)")]));
    assert!(
        e.contains("angular_velocity must be at most 6283.185307179586 rad/s (a thousand turns a second) in length, got 100000"),
        "{e}"
    );
    let e = error(&scene(&[("LENS", ", angular_velocity: (1e300, 1e300, 0.0)")]));
    assert!(e.contains("in length, got more than 1e300"), "{e}");
    let ok = World::from_text(
        &scene(&[(
            "LENS",
            ", shutter: (open: 0.0, close: 0.1), angular_velocity: (0.0, 0.5, 0.0)",
        )]),
        "s.ron",
        Path::new("."),
    )
    .expect("a pan");
    assert!(ok.has_motion, "a turning camera is motion");
}

/// A camera that looks straight down with no `up` written is told what to write, at its
/// `look_at` (a new user's top-down camera read "`up` is parallel", naming a field the
/// file did not have).
#[test]
fn a_top_down_camera_is_told_to_give_an_up() {
    let e = error(&scene(&[("LOOK", "(0.0, -1.0, 3.0)")]));
    assert!(
        e.starts_with("2:50: the camera looks straight up or down, along the default `up` (0, 1, 0): give the camera an `up`"),
        "{e}"
    );
    let e = error(&scene(&[("LOOK", "(0.0, -1.0, 3.0), up: (0.0, 2.0, 0.0)")]));
    assert!(e.contains("`up` is parallel to the viewing direction"), "{e}");
}

/// A syntax error says what stands where something else was expected: the word or the
/// character there, or the end of the line.
#[test]
fn a_syntax_error_says_what_it_found() {
    // Each edit of the scene, and how the error's line ends.
    let cases: &[((&str, &str), &str)] = &[
        (("FOV", "40.0,,"), "Expected identifier, found `,`"),
        (("FOV", "4o"), "`fov` = 4o: not a number"),
        (("FOV", "40.0 width"), "Expected comma, found `width`"),
        // A value of the wrong type names its field and what it needs.
        (("FOV", "\"wide\""), "`fov` = \"wide\": expected a number"),
        (("FOV", "true"), "`fov` = true: expected a number"),
        // A decimal number where a whole number belongs: ron stops at its `.` or at its `e`.
        (
            ("width: 8", "width: 8.0"),
            "`width` = 8.0: expected a whole number, found a decimal number",
        ),
        (
            ("height: 8", "height: 8e0"),
            "`height` = 8e0: expected a whole number, found a decimal number",
        ),
        // A tuple's values: how many, which one has the wrong type, one too many, one
        // missing; a comma missing between two values stays a syntax error.
        (
            ("LOOK", "(0.0, 1.0)"),
            "`look_at` = (0.0, 1.0): expected 3 values, found 2",
        ),
        (
            ("LOOK", "(0.0, nan, 0.0)"),
            "`look_at`: value 2 = nan: expected a finite number, not NaN",
        ),
        (
            ("LOOK", "(0.0, 1.0, 0.0, 2.0)"),
            "`look_at` has more than 3 values (found `2.0`)",
        ),
        (("LOOK", "(0.0, 1.0 0.0)"), "Expected comma, found `0.0`"),
        (
            ("LOOK", "(0.0, , 0.0)"),
            "`look_at`: value 2 is missing: expected a number",
        ),
        // A tuple written over lines, with a comment, echoes on one line.
        (
            ("LOOK", "(0.0, // aim\n        1.0)"),
            "`look_at` = (0.0, 1.0): expected 3 values, found 2",
        ),
        // Named fields given as bare values.
        (
            ("LENS", ", shutter: (0.0, 0.1)"),
            "`shutter`: expected named fields (`name: value`) in the parentheses, found `0.0`",
        ),
    ];
    for &(edit, tail) in cases {
        let e = error(&scene(&[edit]));
        assert!(e.ends_with(tail), "{edit:?}: {e}");
    }
    // A whole number inside a tuple: decimal, exponent, out of range (its sign kept).
    let checker = |checks: &str| {
        let t = r#""c": Diffuse(albedo: (0.5, 0.5, 0.5), texture: "t")"#;
        let mut s = scene(&[("MAT", t)]);
        s = s.replace(
            "materials:",
            &format!("textures: {{ \"t\": Checker(checks: {checks}, a: (0.1, 0.1, 0.1), b: (0.9, 0.9, 0.9)) }},\n    materials:"),
        );
        error(&s)
    };
    let e = checker("(8, 8.5)");
    assert!(
        e.ends_with("`checks`: value 2 = 8.5: expected a whole number, found a decimal number"),
        "{e}"
    );
    let e = checker("(8e0, 8)");
    assert!(
        e.ends_with("`checks`: value 1 = 8e0: expected a whole number, found a decimal number"),
        "{e}"
    );
    let e = checker("(8, -8)");
    assert!(
        e.ends_with("`checks`: value 2 = -8 is out of range for a whole number"),
        "{e}"
    );
    // A byte-order mark does not shift the columns the checks read.
    let e = error(&format!("\u{feff}{}", scene(&[("width: 8", "width: 8.5")])));
    assert!(
        e.ends_with("`width` = 8.5: expected a whole number, found a decimal number"),
        "{e}"
    );
}

/// OBJ files a new user brought: a byte-order mark and a Latin-1 comment are read past;
/// a bad vertex, a bad face, an empty face, a colour of two numbers, a face beyond the
/// vertices or the normals its object has, a NaN coordinate (each with the OBJ's line),
/// a comment after a statement (read past), lines ended by a lone carriage return, faces
/// of no area and a mesh scaled below the least size each say what is wrong, in one
/// positioned line.
#[test]
fn obj_files_say_what_is_wrong_with_them() {
    let dir = std::env::temp_dir().join(format!("covtrace-obj-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let cases: [(&str, Vec<u8>, &str, &str); 16] = [
        ("bom.obj", [&b"\xef\xbb\xbf"[..], tri.as_bytes()].concat(), "", ""),
        (
            "latin1.obj",
            [&b"# mod\xe9lis\xe9\n"[..], tri.as_bytes()].concat(),
            "",
            "",
        ),
        (
            "badnum.obj",
            b"v 1 abc 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".to_vec(),
            "",
            "line 1: a vertex (`v`) whose coordinates are not",
        ),
        (
            "oob.obj",
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n".to_vec(),
            "",
            "line 4: a face (`f`) refers to a vertex (`v`) the file does not have",
        ),
        (
            "badface.obj",
            [tri.as_bytes(), b"f 1 2 x\n"].concat(),
            "",
            "line 5: a face (`f`) whose entries are not",
        ),
        (
            "normal.obj",
            [
                tri.as_bytes(),
                b"vn 0 0 1\nf 1//1 2//1 3//1\nf -1//1 -2//2 -3//1\n",
            ]
            .concat(),
            "",
            "line 7: a face (`f`) refers to a normal (`vn`) the file does not have",
        ),
        // The reader checks an object's indices when it closes the object: a vertex
        // stated later in the same object counts, one stated in the next does not.
        (
            "forward.obj",
            b"v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\n".to_vec(),
            "",
            "",
        ),
        (
            "closed.obj",
            b"v 0 0 0\nv 1 0 0\no a\nf 1 2 3\no b\nv 0 1 0\nf 1 2 3\n".to_vec(),
            "",
            "line 4: a face (`f`) refers to a vertex (`v`) stated only after its object ends",
        ),
        // A comment after a statement is not read as more numbers.
        (
            "comment.obj",
            b"v 0 0 0 # origin\nv 1 0 0\nv 0 1 0\nf 1 2 3 # the face\n".to_vec(),
            "",
            "",
        ),
        (
            "colour.obj",
            [tri.as_bytes(), b"v 0 0 1 0.5 0.5\n"].concat(),
            "",
            "line 5: a vertex (`v`) whose numbers are not three or four coordinates",
        ),
        (
            "empty.obj",
            [tri.as_bytes(), b"f\n"].concat(),
            "",
            "line 5: a face (`f`) without vertices",
        ),
        (
            "mac.obj",
            tri.replace('\n', "\r").into_bytes(),
            "",
            "its lines end with a lone carriage return",
        ),
        (
            "nan.obj",
            b"# a NaN on the file's third line\nv 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n".to_vec(),
            "",
            "line 3: a vertex (`v`) has a coordinate that is not a finite 32-bit number",
        ),
        (
            "e39.obj",
            b"v 0 0 0\nv 1 0 0\nv 1e39 1 0\nf 1 2 3\n".to_vec(),
            "",
            "line 3: a vertex (`v`) has a coordinate that is not a finite 32-bit number (NaN, inf, or past ±3.4e38",
        ),
        (
            "line.obj",
            b"v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n".to_vec(),
            "",
            "every triangle of the file has zero area",
        ),
        (
            "tiny.obj",
            tri.as_bytes().to_vec(),
            ", scale: 1e-300",
            "this mesh is 1e-300 m across",
        ),
    ];
    for (name, bytes, extra, want) in cases {
        let path = dir.join(name);
        std::fs::write(&path, bytes).expect("write OBJ");
        let text = scene(&[(
            "SHAPE",
            &format!(r#"Mesh(obj: "{}", material: "w"{extra})"#, path.display()),
        )]);
        if want.is_empty() {
            let w =
                World::from_text(&text, "s.ron", Path::new(".")).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(w.geometry.len() >= 2, "{name}");
        } else {
            let e = error(&text);
            assert!(e.contains(want), "{name}: {e}");
        }
    }
    std::fs::remove_dir_all(&dir).expect("clean up");
}

/// An OBJ mesh given where a scene belongs says so, not what the RON parser expected.
#[test]
fn a_mesh_given_as_the_scene_says_so() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes/torus.obj");
    let e = cov_render::World::load(&path).unwrap_err().to_string();
    assert!(e.ends_with("an OBJ mesh, not a scene: a scene (`Scene(...)` in RON) places it with a `Mesh(obj: \"…\", material: …)` shape"), "{e}");
}

/// A mesh placed several times is the file's triangles at each place (the file is read
/// once), and the scene's fingerprint reads each file once.
#[test]
fn a_mesh_placed_twice_is_read_once_and_placed_twice() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes");
    let shapes = |n: usize| {
        (0..n)
            .map(|i| format!(r#"Mesh(obj: "torus.obj", material: "w", translate: ({i}.0, 0.0, 0.0))"#))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let world = |n: usize| World::from_text(&scene(&[("SHAPE", &shapes(n))]), "s.ron", &dir).unwrap();
    let (none, one, three) = (world(0), world(1), world(3));
    let mesh = one.geometry.len() - none.geometry.len();
    assert!(mesh > 1000, "{mesh}");
    assert_eq!(three.geometry.len() - none.geometry.len(), 3 * mesh);
    assert_eq!(three.inputs.len(), 1);
}

/// `rotate` turns a mesh about `x`, then `y`, then `z`, with its vertex normals: a
/// triangle in the `xy` plane (normals `+z`) turned 90° about `y` lies in the `yz` plane
/// facing `x`; turned `(90, 90, 0)` it lies in the `xz` plane facing `−y` (the other order
/// would leave it facing `x`), and moved by `translate` after the turn.
#[test]
fn a_mesh_turns_about_x_then_y_then_z() {
    let dir = std::env::temp_dir().join(format!("covtrace-rotate-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    std::fs::write(
        dir.join("tri.obj"),
        "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\n",
    )
    .expect("write");
    let hit = |rotate: &str, from: glam::DVec3, off: glam::DVec3| {
        let text = BASE.replace(
            "shapes: [Sphere(center: (0.0, 0.5, 0.0), radius: 0.5, material: \"w\"), SHAPE]",
            &format!(r#"shapes: [Mesh(obj: "tri.obj", material: "w", rotate: {rotate}, translate: (0.0, 0.0, -20.0))]"#),
        );
        let world = World::from_text(&scene_from(&text), "s.ron", &dir).unwrap_or_else(|e| panic!("{e}"));
        let c = glam::DVec3::new(0.0, 0.0, -20.0);
        world
            .geometry
            .intersect(c + off + from * 5.0, -from, 0.0, 0.0, f64::INFINITY)
            .map(|h| (h.p - c, h.n))
    };
    let (x, y, z, o) = (glam::DVec3::X, glam::DVec3::Y, glam::DVec3::Z, glam::DVec3::ZERO);
    let (p, n) = hit("(0.0, 90.0, 0.0)", x, o).expect("turned to face x");
    assert!(p.length() < 1e-9 && (n - x).length() < 1e-9, "{p} {n}");
    let (p, n) = hit("(90.0, 90.0, 0.0)", -y, o).expect("turned to face -y");
    assert!(p.length() < 1e-9 && (n + y).length() < 1e-9, "{p} {n}");
    // A ray along x above the plane y = 0 misses it; it would meet the plane x = 0.
    assert!(hit("(90.0, 90.0, 0.0)", x, 0.2 * y).is_none(), "not facing x");
    assert!(
        hit("(0.0, 90.0, 0.0)", x, 0.2 * y).is_some(),
        "the plane x = 0 is met off its centre"
    );
    let (_, n) = hit("(0.0, 0.0, 0.0)", z, o).expect("unturned");
    assert!((n - z).length() < 1e-12, "{n}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A mesh placed out of reach is said to be out of reach, as a sphere is, not too small
/// for where it is.
#[test]
fn a_mesh_placed_out_of_reach_says_so() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes");
    for x in ["1e13", "1e300"] {
        let shape = format!(r#"Mesh(obj: "torus.obj", material: "w", translate: ({x}, 0.0, 0.0))"#);
        let e = World::from_text(&scene(&[("SHAPE", &shape)]), "s.ron", &dir)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(&format!("this mesh reaches {x} m from the origin")) && e.contains("holds ±1e12 m"),
            "{e}"
        );
    }
}

/// Copies of one shape in one place are refused at the first past the limit, before the
/// BVH builder, whose time grows as the square of their number; a few copies load.
#[test]
fn copies_of_one_shape_in_one_place_are_refused() {
    let copies =
        |n: usize| vec![r#"Sphere(center: (0.0, 0.5, 0.0), radius: 0.5, material: "w")"#; n].join(", ");
    // With the base scene's own sphere, 256 copies make 257 on one box.
    let e = error(&scene(&[("SHAPE", &copies(256))]));
    // The centre of the 257th sphere on the line: the base's at column 29, then one
    // every 61 characters.
    let col = 29 + 61 * 256;
    assert!(
        e.starts_with(&format!(
            "5:{col}: more than 256 shapes, lights or mesh triangles lie exactly on one another"
        )),
        "{e}"
    );
    assert!(World::from_text(&scene(&[("SHAPE", &copies(255))]), "s.ron", Path::new(".")).is_ok());
    // A quad is two triangles in one box: it counts once, so the 257th quad is refused,
    // not the 129th. Lights likewise.
    let quad =
        r#"Quad(corner: (5.0, 0.0, 0.0), edge_u: (1.0, 0.0, 0.0), edge_v: (0.0, 1.0, 0.0), material: "w")"#;
    let quads = |n: usize| vec![quad; n].join(", ");
    assert!(World::from_text(&scene(&[("SHAPE", &quads(256))]), "s.ron", Path::new(".")).is_ok());
    let e = error(&scene(&[("SHAPE", &quads(257))]));
    assert!(e.contains("more than 256 shapes"), "{e}");
    let rect = r#"Rect(corner: (5.0, 3.0, 0.0), edge_u: (1.0, 0.0, 0.0), edge_v: (0.0, 0.0, 1.0), radiance: (1.0, 1.0, 1.0))"#;
    let rects = |n: usize| format!("[{}]", vec![rect; n].join(", "));
    assert!(World::from_text(&scene(&[("LIGHTS", &rects(256))]), "s.ron", Path::new(".")).is_ok());
    let e = error(&scene(&[("LIGHTS", &rects(257))]));
    assert!(e.contains("more than 256 shapes"), "{e}");
}

/// A number in another base where a decimal belongs says so, at its field (ron reads the
/// leading `0` and the radius check refused 0, or ron stopped at the letter).
#[test]
fn a_number_in_another_base_says_so() {
    for (shape, want) in [
        (
            r#"Sphere(center: (0.0, 0.5, 0.0), radius: 0x1, material: "w")"#,
            "`radius` = 0x1: a hexadecimal number; write it in decimal",
        ),
        (
            r#"Sphere(center: (0.0, 0.5, 0.0), radius: 0b1, material: "w")"#,
            "`radius` = 0b1: a binary number",
        ),
    ] {
        let e = error(&scene(&[("SHAPE", shape)]));
        assert!(e.starts_with("5:115: ") && e.contains(want), "{e}");
    }
}

/// A space character other than a plain space, tab or line break (a no-break space pasted
/// in) is named where it stands, not blamed on the value after it; in a comment it is
/// harmless.
#[test]
fn an_unusual_space_is_named_where_it_stands() {
    let e = error(&scene(&[("FOV", "\u{a0}40.0")]));
    assert!(e.starts_with("2:72: a U+00A0 space character here"), "{e}");
    let commented = scene(&[("FOV", "40.0 /* a\u{a0}b */")]);
    assert!(World::from_text(&commented, "s.ron", Path::new(".")).is_ok());
}

/// An OBJ whose `usemtl` lines name several materials loads with one material, the
/// scene's, and says so in one warning; one named material is no warning (the mesh's
/// material is the scene's choice).
#[test]
fn an_obj_of_several_materials_is_a_warning() {
    let dir = std::env::temp_dir().join(format!("covtrace-usemtl-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let two =
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nusemtl light\nf 1 2 3\n  usemtl\tdark\nf 2 4 3\nusemtl light\n";
    std::fs::write(dir.join("two.obj"), two).expect("write");
    std::fs::write(
        dir.join("one.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl light\nf 1 2 3\n",
    )
    .expect("write");
    let world = |obj: &str| {
        let text = scene(&[("SHAPE", &format!(r#"Mesh(obj: "{obj}", material: "w")"#))]);
        World::from_text(&text, "s.ron", &dir).expect("the mesh loads")
    };
    let w = world("two.obj");
    assert_eq!(w.warnings.len(), 1, "{:?}", w.warnings);
    let m = &w.warnings[0];
    // Positioned at the mesh's OBJ, as an error would be.
    assert!(m.starts_with("s.ron:5:85: OBJ"), "{m}");
    assert!(
        m.contains("OBJ `two.obj` names 2 materials with `usemtl` (`light`, `dark`)")
            && m.contains("all of it is `w`")
            && !m.contains('\n'),
        "{m}"
    );
    assert!(world("one.obj").warnings.is_empty());
    let _ = std::fs::remove_dir_all(&dir);
}

/// A scene without shapes loads (the lights are seen) and says, once, at `shapes`, that
/// light falls on nothing; a scene with a shape says nothing.
#[test]
fn a_scene_without_shapes_is_a_warning() {
    let text = scene(&[]).replace(
        r#"[Sphere(center: (0.0, 0.5, 0.0), radius: 0.5, material: "w")]"#,
        "[]",
    );
    assert!(text.contains("shapes: []"), "{text}");
    let w = World::from_text(&text, "s.ron", Path::new(".")).expect("loads");
    assert_eq!(w.warnings.len(), 1, "{:?}", w.warnings);
    assert!(
        w.warnings[0].starts_with("s.ron:5:13: `shapes` is empty"),
        "{}",
        w.warnings[0]
    );
    let w = World::from_text(&scene(&[]), "s.ron", Path::new(".")).expect("loads");
    assert!(w.warnings.is_empty(), "{:?}", w.warnings);
}
