//! `<asset><hfield>`: height fields as MuJoCo reads them (xml_native_reader.cc's hfield section,
//! `mjCHField::LoadPNG`, `LoadCustom` and `Compile` in user_objects.cc) — from a grayscale PNG
//! (rows reversed: the image's top line is the highest y), from MuJoCo's binary format (int32
//! nrow, int32 ncol, then nrow·ncol float32, native byte order, nothing else), or from `nrow`,
//! `ncol` and the `elevation` attribute (rows reversed as for the image; all zero when absent);
//! then normalised to [0, 1] ([`HeightField::new`]). Geoms of type `hfield` receive the compiled
//! grid by the asset's name ([`resolve`]).

use super::attrs::Attrs;
use super::xml::Element;
use super::Compiler;
use crate::io::LoadError;
use crate::model::spec::{LinkSpec, Shape};
use crate::model::HeightField;
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

/// The most grid points a height field may have (a resource limit against a corrupt header).
const MAX_POINTS: usize = 1 << 28;

/// Every `<hfield>` asset by name (an unnamed one is named after its file, extension removed).
pub(crate) fn hfields(
    root: &Element,
    compiler: &Compiler,
    main_file: &str,
) -> Result<HashMap<String, Arc<HeightField>>, LoadError> {
    let mut out = HashMap::new();
    for section in root.children_named("asset") {
        for e in section.children_named("hfield") {
            let a = Attrs::plain(e);
            let field = hfield(&a, e, compiler, main_file)?;
            let name = match (a.text("name"), a.text("file")) {
                (Some(n), _) => n.to_string(),
                (None, Some(f)) => Path::new(f).file_stem().and_then(|s| s.to_str()).unwrap_or(f).to_string(),
                (None, None) => continue,
            };
            if out.insert(name.clone(), Arc::new(field)).is_some() {
                return Err(LoadError::DuplicateName { loc: e.loc.clone(), element: "hfield", name });
            }
        }
    }
    Ok(out)
}

fn hfield(a: &Attrs, e: &Element, compiler: &Compiler, main_file: &str) -> Result<HeightField, LoadError> {
    let size = a.array::<4>("size")?.unwrap_or([0.0; 4]);
    if size.iter().any(|&s| s <= 0.0) {
        return Err(a.error("size", "needs 4 positive values: radius_x radius_y elevation_z base_z"));
    }
    let dims = |name: &str| -> Result<usize, LoadError> {
        match a.int(name)? {
            None => Ok(0),
            Some(n) if (0..=MAX_POINTS as i64).contains(&n) => Ok(n as usize),
            Some(_) => Err(a.error(name, "must be between 0 and 2^28")),
        }
    };
    let (nrow, ncol) = (dims("nrow")?, dims("ncol")?);
    let (nrow, ncol, data) = match a.text("file") {
        Some(file) => {
            if nrow != 0 || ncol != 0 || a.has("elevation") {
                return Err(a.error(
                    "file",
                    "and nrow/ncol/elevation both given: the grid comes from one or the other",
                ));
            }
            let mut path = compiler.meshdir.join(file);
            if !path.is_file() && e.loc.file != main_file {
                if let Some(dir) = Path::new(&e.loc.file).parent() {
                    if dir.join(file).is_file() {
                        path = dir.join(file);
                    }
                }
            }
            if !path.is_file() {
                return Err(LoadError::AssetNotFound {
                    loc: e.loc.clone(),
                    element: "hfield".into(),
                    path: path.display().to_string(),
                });
            }
            let bytes = std::fs::read(&path)
                .map_err(|err| a.error("file", format!("'{}' could not be read: {err}", path.display())))?;
            let png = match a.text("content_type") {
                Some("image/png") => true,
                Some("image/vnd.mujoco.hfield") => false,
                Some(other) => {
                    return Err(a.error(
                        "content_type",
                        format!("'{other}' is not image/png or image/vnd.mujoco.hfield"),
                    ))
                }
                None => {
                    path.extension().and_then(|x| x.to_str()).is_some_and(|x| x.eq_ignore_ascii_case("png"))
                }
            };
            let read = if png { read_png(&bytes) } else { read_binary(&bytes) };
            read.map_err(|why| a.error("file", format!("'{}': {why}", path.display())))?
        }
        None => {
            if nrow == 0 || ncol == 0 {
                return Err(a.error("nrow", "and ncol must be positive when there is no file"));
            }
            if nrow.saturating_mul(ncol) > MAX_POINTS {
                return Err(a.error("nrow", "× ncol exceeds 2^28 points"));
            }
            let data = match a.numbers("elevation")? {
                Some(v) => {
                    if v.len() != nrow * ncol {
                        return Err(a.error(
                            "elevation",
                            format!("has {} values, nrow·ncol = {}", v.len(), nrow * ncol),
                        ));
                    }
                    // The text reads top to bottom: its first line is the last row.
                    let mut flipped = vec![0.0_f32; nrow * ncol];
                    for (i, line) in v.chunks(ncol).enumerate() {
                        let r = nrow - 1 - i;
                        for (c, x) in line.iter().enumerate() {
                            flipped[r * ncol + c] = *x as f32;
                        }
                    }
                    flipped
                }
                None => vec![0.0; nrow * ncol],
            };
            (nrow, ncol, data)
        }
    };
    Ok(HeightField::new(nrow, ncol, size, data))
}

/// A PNG as MuJoCo reads it for a height field: decoded to 8-bit grey the way its PNG decoder
/// (lodepng, asked for `LCT_GREY`) converts — a grey image keeps its value, a colour or palette
/// image keeps its **red** channel, 16-bit samples keep their high byte, alpha is ignored — rows
/// reversed.
fn read_png(bytes: &[u8]) -> Result<(usize, usize, Vec<f32>), String> {
    let mut decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = decoder.read_info().map_err(|e| format!("not a readable PNG ({e})"))?;
    let size = reader.output_buffer_size().ok_or("PNG too large")?;
    let mut buf = vec![0u8; size];
    let info = reader.next_frame(&mut buf).map_err(|e| format!("not a readable PNG ({e})"))?;
    let channels = match info.color_type {
        png::ColorType::Grayscale => 1,
        png::ColorType::GrayscaleAlpha => 2,
        png::ColorType::Rgb => 3,
        png::ColorType::Rgba => 4,
        // EXPAND turns palette images into Rgb/Rgba before this point.
        png::ColorType::Indexed => return Err("a palette PNG the decoder did not expand".into()),
    };
    let (ncol, nrow) = (info.width as usize, info.height as usize);
    if nrow == 0 || ncol == 0 {
        return Err("an empty image".into());
    }
    let mut data = Vec::with_capacity(nrow * ncol);
    for r in 0..nrow {
        let line = &buf[(nrow - 1 - r) * info.line_size..];
        for c in 0..ncol {
            data.push(f32::from(line[c * channels]));
        }
    }
    Ok((nrow, ncol, data))
}

/// MuJoCo's binary format: int32 nrow, int32 ncol, then nrow·ncol float32 (native byte order).
fn read_binary(bytes: &[u8]) -> Result<(usize, usize, Vec<f32>), String> {
    if bytes.len() < 8 {
        return Err("shorter than its 8-byte header (int32 nrow, int32 ncol)".into());
    }
    let int = |i: usize| i32::from_ne_bytes([bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]);
    let (nrow, ncol) = (int(0), int(4));
    if nrow < 1 || ncol < 1 {
        return Err(format!("non-positive dimensions {nrow} × {ncol}"));
    }
    let n = (nrow as usize).saturating_mul(ncol as usize);
    if n > MAX_POINTS || bytes.len() != 8 + 4 * n {
        return Err(format!("{} bytes, a {nrow} × {ncol} grid needs {}", bytes.len(), 8 + 4 * n));
    }
    let data = bytes[8..].chunks_exact(4).map(|b| f32::from_ne_bytes([b[0], b[1], b[2], b[3]])).collect();
    Ok((nrow as usize, ncol as usize, data))
}

/// Gives every `hfield` geom of `links` the grid of the asset it names.
pub(crate) fn resolve(
    links: &mut [LinkSpec],
    fields: &HashMap<String, Arc<HeightField>>,
) -> Result<(), LoadError> {
    for g in links.iter_mut().flat_map(|l| l.geoms.iter_mut()) {
        if let Shape::Hfield { name, field } = &mut g.shape {
            match fields.get(name.as_str()) {
                Some(f) => *field = f.clone(),
                None => {
                    return Err(LoadError::UnknownReference {
                        loc: g.loc.clone(),
                        element: "geom".into(),
                        kind: "hfield",
                        target: name.clone(),
                    })
                }
            }
        }
    }
    Ok(())
}
