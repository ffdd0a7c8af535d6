//! `<hfield>` loading: the elevation attribute, MuJoCo's binary format and a grayscale PNG give
//! MuJoCo's normalised `hfield_data` (rows reversed for the text and the image), and a height field
//! geom on a body weighs as MuJoCo's box (size[0], size[1], size[2]/4 + size[3]/2). Reference
//! numbers: MuJoCo 4.0.0's `m.hfield_data`, `m.body_mass`, `m.body_inertia` for the scene below.

mod common;

use lagrange::model::spec::Shape;
use lagrange::model::HeightField;

const ELEVATION: &str = r#"<mujoco><asset><hfield name="h" nrow="3" ncol="4" size="1 0.8 0.3 0.1" elevation="0 1 2 3  1 1 1 1  3 2 0 1"/></asset>
<worldbody><body><freejoint/><geom type="hfield" hfield="h" density="500"/></body></worldbody></mujoco>"#;

/// MuJoCo 4.0.0's `hfield_data` for ELEVATION (float32 values, as f32).
const MUJOCO_DATA: [f32; 12] = [
    1.0, 0.6666667, 0.0, 0.33333334, 0.33333334, 0.33333334, 0.33333334, 0.33333334, 0.0, 0.33333334,
    0.6666667, 1.0,
];

fn field(model: &lagrange::Model) -> &HeightField {
    match &model.geoms[0].shape {
        Shape::Hfield { field, .. } => field,
        other => panic!("geom 0 is {other:?}"),
    }
}

#[test]
fn elevation_attribute_as_mujoco() {
    let model = common::load_mjcf_text("hfield", "elevation", ELEVATION);
    let f = field(&model);
    assert_eq!((f.nrow, f.ncol), (3, 4));
    assert_eq!(f.size, [1.0, 0.8, 0.3, 0.1]);
    assert_eq!(f.data, MUJOCO_DATA);
    // MuJoCo: body_mass 400, body_inertia 87.41666667 135.41666667 218.66666667.
    let b = &model.bodies[model.bodies.len() - 1];
    assert!((b.mass() - 400.0).abs() < 1e-12, "{}", b.mass());
    let i = b.inertia_com();
    for (k, want) in [87.41666666666667, 135.41666666666667, 218.66666666666666].iter().enumerate() {
        assert!((i[(k, k)] - want).abs() < 1e-9, "{k}: {} vs {want}", i[(k, k)]);
    }
}

/// The same grid as ELEVATION in row order (row 0 = the text's last line).
const ROWS: [[f32; 4]; 3] = [[3.0, 2.0, 0.0, 1.0], [1.0, 1.0, 1.0, 1.0], [0.0, 1.0, 2.0, 3.0]];

#[test]
fn binary_and_png_files_as_mujoco() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("lagrange-hfield-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // Binary: int32 nrow, int32 ncol, float32 data, row 0 first.
    let mut bin = Vec::new();
    bin.extend_from_slice(&3i32.to_ne_bytes());
    bin.extend_from_slice(&4i32.to_ne_bytes());
    for v in ROWS.iter().flatten() {
        bin.extend_from_slice(&v.to_ne_bytes());
    }
    std::fs::write(dir.join("h.bin"), &bin).unwrap();
    // PNG: the image's top line is the last row.
    let mut png_bytes = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut png_bytes, 4, 3);
        enc.set_color(png::ColorType::Grayscale);
        enc.set_depth(png::BitDepth::Eight);
        let mut w = enc.write_header().unwrap();
        let pixels: Vec<u8> = ROWS.iter().rev().flatten().map(|&v| (v * 60.0) as u8).collect();
        w.write_image_data(&pixels).unwrap();
    }
    std::fs::write(dir.join("h.png"), &png_bytes).unwrap();
    // Colour images: MuJoCo's decoder (lodepng asked for grey) keeps the red channel and
    // ignores green, blue and alpha; a palette image keeps its palette entry's red.
    let heights: Vec<u8> = ROWS.iter().rev().flatten().map(|&v| (v * 60.0) as u8).collect();
    for (name, color, channels) in
        [("rgb.png", png::ColorType::Rgb, 3), ("rgba.png", png::ColorType::Rgba, 4)]
    {
        let mut bytes = Vec::new();
        let mut enc = png::Encoder::new(&mut bytes, 4, 3);
        enc.set_color(color);
        enc.set_depth(png::BitDepth::Eight);
        let mut w = enc.write_header().unwrap();
        let pixels: Vec<u8> =
            heights.iter().flat_map(|&h| [h, 255 - h, 7, 100].into_iter().take(channels)).collect();
        w.write_image_data(&pixels).unwrap();
        drop(w);
        std::fs::write(dir.join(name), &bytes).unwrap();
    }
    {
        let mut bytes = Vec::new();
        let mut enc = png::Encoder::new(&mut bytes, 4, 3);
        enc.set_color(png::ColorType::Indexed);
        enc.set_depth(png::BitDepth::Eight);
        let palette: Vec<u8> = (0..=255u8).flat_map(|i| [i, 0, 255 - i]).collect();
        enc.set_palette(palette);
        let mut w = enc.write_header().unwrap();
        w.write_image_data(&heights).unwrap();
        drop(w);
        std::fs::write(dir.join("palette.png"), &bytes).unwrap();
    }
    for file in ["h.bin", "h.png", "rgb.png", "rgba.png", "palette.png"] {
        let xml = format!(
            r#"<mujoco><asset><hfield name="h" file="{}" size="1 0.8 0.3 0.1"/></asset><worldbody><geom type="hfield" hfield="h"/></worldbody></mujoco>"#,
            dir.join(file).display()
        );
        let path = dir.join(format!("{file}.xml"));
        std::fs::write(&path, xml).unwrap();
        let model = lagrange::io::load(&path, &Default::default()).unwrap();
        assert_eq!(field(&model).data, MUJOCO_DATA, "{file}");
    }
}

#[test]
fn bad_hfields_are_typed_errors() {
    for (xml, says) in [
        (ELEVATION.replace(r#"hfield="h" density"#, r#"hfield="nope" density"#), "unknown hfield 'nope'"),
        (ELEVATION.replace("0 1 2 3  1 1 1 1", "0 1 2 3"), "elevation"),
        (ELEVATION.replace(r#"size="1 0.8 0.3 0.1""#, r#"size="1 0.8 0.3 0""#), "positive"),
    ] {
        let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
            .join(format!("lagrange-hfield-bad-{}.xml", std::process::id()));
        std::fs::write(&path, xml).unwrap();
        let err = lagrange::io::load(&path, &Default::default()).unwrap_err().to_string();
        assert!(err.contains(says), "{err}");
    }
}
