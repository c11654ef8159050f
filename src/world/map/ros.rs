//! ROS `map_server` occupancy grids: a YAML file (`image`, `resolution`, `origin`, `negate`,
//! `occupied_thresh`, `free_thresh`, `mode`) and its image, a PGM (binary P5 or text P2) or a
//! PNG, read as `map_server` reads them: a pixel `v` (0–255; colour pixels are averaged) has
//! occupancy `p = (255 − v) / 255` (`v / 255` with `negate: 1`); `p > occupied_thresh` is
//! occupied, `p < free_thresh` free, anything between unknown (`mode: trinary` and `scale`
//! classify alike; `raw` maps are not read). The image's top row is the map's top; `origin` is
//! the pose of its lower-left pixel, and only a zero yaw is accepted.
//!
//! The YAML is the flat `key: value` form every map server writes; it is read here, with a
//! located error for anything else, rather than through a general YAML library.

use std::path::Path;

use super::{CellState, MapError, Occupancy};

/// Reads a map from its YAML file.
pub fn read(yaml: &Path) -> Result<Occupancy, MapError> {
    let text = std::fs::read_to_string(yaml)
        .map_err(|e| MapError::at(yaml, None, format!("cannot read the map: {e}")))?;
    let meta = Metadata::parse(&text, yaml)?;
    let image = yaml.parent().unwrap_or(Path::new(".")).join(&meta.image);
    let (width, height, pixels) = read_image(&image)?;
    let mut cells = vec![CellState::Free; width * height];
    for row in 0..height {
        // The image's first row is the map's top.
        let j = height - 1 - row;
        for i in 0..width {
            let v = f64::from(pixels[row * width + i]);
            let p = if meta.negate {
                v / 255.0
            } else {
                (255.0 - v) / 255.0
            };
            cells[j * width + i] = if p > meta.occupied_thresh {
                CellState::Blocked
            } else if p < meta.free_thresh {
                CellState::Free
            } else {
                CellState::Unknown
            };
        }
    }
    Ok(Occupancy {
        file: yaml.to_path_buf(),
        width,
        height,
        cell: meta.resolution,
        origin: meta.origin,
        cells,
        unknown_blocked: true,
    })
}

/// The keys of a map's YAML.
#[derive(Debug, Clone, PartialEq)]
struct Metadata {
    image: String,
    resolution: f64,
    origin: [f64; 2],
    negate: bool,
    occupied_thresh: f64,
    free_thresh: f64,
}

impl Metadata {
    fn parse(text: &str, file: &Path) -> Result<Self, MapError> {
        let mut image = None;
        let mut resolution = None;
        let mut origin = None;
        let mut negate = false;
        let mut occupied_thresh = 0.65;
        let mut free_thresh = 0.196;
        for (n, raw) in text.lines().enumerate() {
            let at =
                |column: usize, message: String| MapError::at(file, Some((n + 1, column)), message);
            let line = raw.split('#').next().unwrap_or("").trim_end();
            if line.trim().is_empty() {
                continue;
            }
            let Some((key, value)) = line.split_once(':') else {
                return Err(at(
                    1,
                    format!("expected `key: value`, found `{}`", line.trim()),
                ));
            };
            let (key, value) = (key.trim(), value.trim());
            let column = raw.find(value).map_or(1, |c| c + 1);
            let number = |what: &str| -> Result<f64, MapError> {
                value
                    .parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| at(column, format!("`{what}` must be a number, got `{value}`")))
            };
            match key {
                "image" => image = Some(value.trim_matches(['"', '\'']).to_string()),
                "resolution" => {
                    let r = number("resolution")?;
                    if r <= 0.0 {
                        return Err(at(
                            column,
                            format!("`resolution` must be positive, got {r}"),
                        ));
                    }
                    resolution = Some(r);
                }
                "origin" => {
                    let items: Vec<&str> = value
                        .strip_prefix('[')
                        .and_then(|v| v.strip_suffix(']'))
                        .map(|v| v.split(',').map(str::trim).collect())
                        .unwrap_or_default();
                    let numbers: Option<Vec<f64>> = items
                        .iter()
                        .map(|x| x.parse::<f64>().ok().filter(|x| x.is_finite()))
                        .collect();
                    match numbers.as_deref() {
                        Some([x, y, yaw]) => {
                            if *yaw != 0.0 {
                                return Err(at(
                                    column,
                                    format!(
                                        "a rotated map (yaw {yaw}) is not supported; rotate the image instead"
                                    ),
                                ));
                            }
                            origin = Some([*x, *y]);
                        }
                        _ => {
                            return Err(at(
                                column,
                                format!("`origin` must be `[x, y, yaw]`, got `{value}`"),
                            ));
                        }
                    }
                }
                "negate" => {
                    negate = match value {
                        "0" | "false" => false,
                        "1" | "true" => true,
                        _ => {
                            return Err(at(
                                column,
                                format!("`negate` must be 0 or 1, got `{value}`"),
                            ));
                        }
                    }
                }
                "occupied_thresh" => occupied_thresh = number("occupied_thresh")?,
                "free_thresh" => free_thresh = number("free_thresh")?,
                "mode" => match value {
                    "trinary" | "scale" => {}
                    other => {
                        return Err(at(
                            column,
                            format!("mode `{other}` is not supported (trinary or scale)"),
                        ));
                    }
                },
                other => {
                    return Err(at(
                        1,
                        format!(
                            "unknown key `{other}` (a map's YAML has image, resolution, origin, negate, occupied_thresh, free_thresh, mode)"
                        ),
                    ));
                }
            }
        }
        let missing = |key: &str| MapError::at(file, None, format!("missing key `{key}`"));
        if !(0.0..=1.0).contains(&free_thresh)
            || !(0.0..=1.0).contains(&occupied_thresh)
            || free_thresh > occupied_thresh
        {
            return Err(MapError::at(
                file,
                None,
                format!(
                    "the thresholds must satisfy 0 ≤ free_thresh ≤ occupied_thresh ≤ 1, got {free_thresh} and {occupied_thresh}"
                ),
            ));
        }
        Ok(Self {
            image: image.ok_or_else(|| missing("image"))?,
            resolution: resolution.ok_or_else(|| missing("resolution"))?,
            origin: origin.ok_or_else(|| missing("origin"))?,
            negate,
            occupied_thresh,
            free_thresh,
        })
    }
}

/// An image's width, height and grey levels (0–255), top row first.
fn read_image(file: &Path) -> Result<(usize, usize, Vec<u8>), MapError> {
    let bytes = std::fs::read(file)
        .map_err(|e| MapError::at(file, None, format!("cannot read the map's image: {e}")))?;
    if bytes.starts_with(b"\x89PNG") {
        read_png(&bytes, file)
    } else if bytes.starts_with(b"P5") || bytes.starts_with(b"P2") {
        read_pgm(&bytes, file)
    } else {
        Err(MapError::at(
            file,
            None,
            "not a PGM (P5 or P2) or PNG image",
        ))
    }
}

/// A binary (P5) or text (P2) PGM.
fn read_pgm(bytes: &[u8], file: &Path) -> Result<(usize, usize, Vec<u8>), MapError> {
    let error = |message: String| MapError::at(file, None, message);
    // The header: magic, width, height, maxval, separated by white space and comments.
    let mut pos = 2;
    let mut field = |what: &str| -> Result<usize, MapError> {
        loop {
            while pos < bytes.len() && bytes[pos].is_ascii_whitespace() {
                pos += 1;
            }
            if pos < bytes.len() && bytes[pos] == b'#' {
                while pos < bytes.len() && bytes[pos] != b'\n' {
                    pos += 1;
                }
                continue;
            }
            break;
        }
        let start = pos;
        while pos < bytes.len() && bytes[pos].is_ascii_digit() {
            pos += 1;
        }
        std::str::from_utf8(&bytes[start..pos])
            .ok()
            .and_then(|s| s.parse().ok())
            .filter(|&v: &usize| v > 0)
            .ok_or_else(|| {
                error(format!(
                    "the PGM header's {what} is missing or not a positive number"
                ))
            })
    };
    let width = field("width")?;
    let height = field("height")?;
    let maxval = field("maximum value")?;
    if maxval > 65535 {
        return Err(error(format!(
            "the PGM maximum value {maxval} is above 65535"
        )));
    }
    let count = width
        .checked_mul(height)
        .filter(|&c| c <= 1 << 30)
        .ok_or_else(|| error(format!("a {width} × {height} image is too large")))?;
    let scale = |v: usize| ((v * 255 + maxval / 2) / maxval).min(255) as u8;
    let pixels: Vec<u8> = if bytes.starts_with(b"P5") {
        // Exactly one white-space byte after maxval, then the raster.
        let data = &bytes[(pos + 1).min(bytes.len())..];
        let sample = if maxval < 256 { 1 } else { 2 };
        if data.len() < count * sample {
            return Err(error(format!(
                "the PGM is truncated: {} bytes of pixels for {width} × {height}",
                data.len()
            )));
        }
        (0..count)
            .map(|k| {
                let v = if sample == 1 {
                    usize::from(data[k])
                } else {
                    usize::from(data[2 * k]) << 8 | usize::from(data[2 * k + 1])
                };
                scale(v.min(maxval))
            })
            .collect()
    } else {
        let text = String::from_utf8_lossy(&bytes[pos..]);
        let values: Vec<usize> = text
            .split(|c: char| c.is_ascii_whitespace())
            .filter(|s| !s.is_empty())
            .map(|s| s.parse::<usize>())
            .collect::<Result<_, _>>()
            .map_err(|_| error("the P2 PGM has a pixel that is not a whole number".into()))?;
        if values.len() < count {
            return Err(error(format!(
                "the PGM is truncated: {} pixels for {width} × {height}",
                values.len()
            )));
        }
        values[..count]
            .iter()
            .map(|&v| scale(v.min(maxval)))
            .collect()
    };
    Ok((width, height, pixels))
}

/// A PNG, in grey levels (colour averaged, 16-bit scaled down, alpha ignored).
fn read_png(bytes: &[u8], file: &Path) -> Result<(usize, usize, Vec<u8>), MapError> {
    let error =
        |e: png::DecodingError| MapError::at(file, None, format!("cannot decode the PNG: {e}"));
    let mut decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = decoder.read_info().map_err(error)?;
    let size = reader
        .output_buffer_size()
        .ok_or_else(|| MapError::at(file, None, "the PNG is too large"))?;
    let mut buffer = vec![0; size];
    let info = reader.next_frame(&mut buffer).map_err(error)?;
    let (width, height) = (info.width as usize, info.height as usize);
    let channels = info.color_type.samples();
    let stride = info.line_size;
    let mut pixels = Vec::with_capacity(width * height);
    for row in buffer[..info.buffer_size()].chunks(stride) {
        for px in row.chunks(channels).take(width) {
            let grey = match channels {
                1 | 2 => px[0],
                _ => ((u16::from(px[0]) + u16::from(px[1]) + u16::from(px[2])) / 3) as u8,
            };
            pixels.push(grey);
        }
    }
    Ok((width, height, pixels))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(dir: &Path, name: &str, bytes: &[u8]) {
        std::fs::write(dir.join(name), bytes).unwrap();
    }

    /// A 3 × 2 image: top row free, occupied, unknown; bottom row occupied, free, free.
    fn pgm_p5() -> Vec<u8> {
        let mut bytes = b"P5\n# made by hand\n3 2\n255\n".to_vec();
        bytes.extend_from_slice(&[254, 0, 205, 0, 254, 254]);
        bytes
    }

    const YAML: &str = "image: m.pgm\nresolution: 0.5\norigin: [-1.0, 2.0, 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\nmode: trinary\n";

    #[test]
    fn a_p5_map_reads_with_its_origin_trinary_and_y_up() {
        let dir = tempfile::tempdir().unwrap();
        write(dir.path(), "m.pgm", &pgm_p5());
        write(dir.path(), "m.yaml", YAML.as_bytes());
        let m = read(&dir.path().join("m.yaml")).unwrap();
        assert_eq!(
            (m.width, m.height, m.cell, m.origin),
            (3, 2, 0.5, [-1.0, 2.0])
        );
        // Bottom row (j = 0) is the image's last row.
        assert_eq!(
            m.cells,
            [
                CellState::Blocked,
                CellState::Free,
                CellState::Free,
                CellState::Free,
                CellState::Blocked,
                CellState::Unknown
            ]
        );
        // Negated, free and occupied swap (unknown stays between).
        write(
            dir.path(),
            "n.yaml",
            YAML.replace("negate: 0", "negate: 1").as_bytes(),
        );
        let n = read(&dir.path().join("n.yaml")).unwrap();
        assert_eq!(n.cells[0], CellState::Free);
        assert_eq!(n.cells[1], CellState::Blocked);
    }

    #[test]
    fn p2_and_png_images_read_like_p5() {
        let dir = tempfile::tempdir().unwrap();
        write(dir.path(), "m.pgm", &pgm_p5());
        write(dir.path(), "m.yaml", YAML.as_bytes());
        let p5 = read(&dir.path().join("m.yaml")).unwrap();
        write(dir.path(), "m.pgm", b"P2\n3 2\n15\n15 0 12\n0 15 15\n");
        assert_eq!(read(&dir.path().join("m.yaml")).unwrap().cells, p5.cells);
        let png = crate::field::export::png(
            &[
                254, 254, 254, 0, 0, 0, 205, 205, 205, 0, 0, 0, 254, 254, 254, 254, 254, 254,
            ],
            3,
            2,
        );
        write(dir.path(), "p.png", &png);
        write(
            dir.path(),
            "p.yaml",
            YAML.replace("m.pgm", "p.png").as_bytes(),
        );
        assert_eq!(read(&dir.path().join("p.yaml")).unwrap().cells, p5.cells);
    }

    #[test]
    fn malformed_maps_are_located_errors() {
        let dir = tempfile::tempdir().unwrap();
        let mut truncated = pgm_p5();
        truncated.truncate(truncated.len() - 2);
        write(dir.path(), "m.pgm", &truncated);
        write(dir.path(), "m.yaml", YAML.as_bytes());
        let e = read(&dir.path().join("m.yaml")).unwrap_err();
        assert!(
            e.file.ends_with("m.pgm") && e.message.contains("truncated"),
            "{e}"
        );
        write(dir.path(), "m.pgm", &pgm_p5());
        write(
            dir.path(),
            "r.yaml",
            YAML.replace("resolution: 0.5\n", "").as_bytes(),
        );
        let e = read(&dir.path().join("r.yaml")).unwrap_err();
        assert!(e.message.contains("missing key `resolution`"), "{e}");
        write(
            dir.path(),
            "o.yaml",
            YAML.replace("0.0]", "0.0, 4]").as_bytes(),
        );
        let e = read(&dir.path().join("o.yaml")).unwrap_err();
        assert_eq!(e.location, Some((3, 9)), "{e}");
        write(
            dir.path(),
            "k.yaml",
            format!("{YAML}colour: red\n").as_bytes(),
        );
        let e = read(&dir.path().join("k.yaml")).unwrap_err();
        assert!(
            e.to_string().contains("k.yaml:8:1: unknown key `colour`"),
            "{e}"
        );
        write(
            dir.path(),
            "y.yaml",
            YAML.replace(", 0.0]", ", 0.5]").as_bytes(),
        );
        assert!(
            read(&dir.path().join("y.yaml"))
                .unwrap_err()
                .message
                .contains("rotated")
        );
    }
}
