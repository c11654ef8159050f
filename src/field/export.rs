//! Writing a solved field for other tools: NumPy `.npy` arrays (read with `numpy.load`).
//!
//! Arrays have shape `[nx, ny]`, x index first: element `[i, j]` is cell `(i, j)`, whose centre
//! is `grid.origin + ((i + ½)·h, (j + ½)·h)`. A shaped agent's field has shape
//! `[nx, ny, headings]`: element `[i, j, k]` is that cell at the heading `k · 2π / headings`.
//! An arm's has one axis per joint, `[cells, cells(, cells)]`: element `[k₁, k₂(, k₃)]` is the
//! cell of those joint cells (see [`super::JointAxis::center`]).

use std::io::Write;

use super::grid::Grid;
use super::{HarmonicField, JointField, PoseField, ScaledW};

/// The class of a cell in the mask array, stored as its `u8` value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum CellClass {
    /// A free cell connected to the target.
    Reachable = 0,
    /// A blocked cell: the agent's centre cannot be there.
    Blocked = 1,
    /// A free cell no path connects to the target.
    Unreachable = 2,
}

impl CellClass {
    /// The class of a cell that is `blocked` or not, and `reachable` from the target or not.
    pub fn of(blocked: bool, reachable: bool) -> Self {
        if blocked {
            Self::Blocked
        } else if reachable {
            Self::Reachable
        } else {
            Self::Unreachable
        }
    }
}

/// Columns of the grid a tile of [`write_npy`] takes at once: the grid's rows are read across
/// the tile and the array's rows (one per column) written down it, both in cache. Element by
/// element in the array's order, each read was a row apart (8 kB at 1025²).
const TILE: usize = 16;

/// Writes an `.npy` file (format 1.0) of a C-ordered `[nx, ny]` array to `out`: element
/// `[i, j]` is `element(grid.index(i, j))`, `B` bytes of `descr`. It goes out a tile of
/// [`TILE`] columns at a time, so a file is never held whole in memory (at 1025², the four
/// arrays of a field were 25 MB, every page of it faulted in fresh).
fn write_npy<const B: usize>(
    out: &mut dyn Write,
    grid: &Grid,
    descr: &str,
    element: impl Fn(usize) -> [u8; B],
) -> std::io::Result<()> {
    out.write_all(&npy_header(&[grid.nx, grid.ny], descr))?;
    let mut tile = vec![0; TILE.min(grid.nx) * grid.ny * B];
    for i0 in (0..grid.nx).step_by(TILE) {
        let columns = i0..(i0 + TILE).min(grid.nx);
        for j in 0..grid.ny {
            for (c, i) in columns.clone().enumerate() {
                let at = (c * grid.ny + j) * B;
                tile[at..at + B].copy_from_slice(&element(grid.index(i, j)));
            }
        }
        out.write_all(&tile[..columns.len() * grid.ny * B])?;
    }
    Ok(())
}

/// What `write` writes, in memory.
fn in_memory(write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> Vec<u8> {
    let mut out = Vec::new();
    write(&mut out).expect("writing to memory");
    out
}

/// An `.npy` file of a C-ordered array of `shape`, its elements' bytes in that order.
fn npy_of<const B: usize>(
    shape: &[usize],
    descr: &str,
    elements: impl Iterator<Item = [u8; B]>,
) -> Vec<u8> {
    let mut out = npy_header(shape, descr);
    out.reserve(shape.iter().product::<usize>() * B);
    for e in elements {
        out.extend_from_slice(&e);
    }
    out
}

/// The header of an `.npy` file of a C-ordered array of `shape` of `descr`: the magic string,
/// the version, the header's length and the header, padded to a multiple of 64 bytes.
fn npy_header(shape: &[usize], descr: &str) -> Vec<u8> {
    let dims: Vec<String> = shape.iter().map(ToString::to_string).collect();
    let mut header = format!(
        "{{'descr': '{descr}', 'fortran_order': False, 'shape': ({}), }}",
        dims.join(", ")
    );
    // Magic (6) + version (2) + length (2) + header + newline, padded to a multiple of 64.
    let unpadded = 10 + header.len() + 1;
    header.push_str(&" ".repeat(unpadded.next_multiple_of(64) - unpadded));
    header.push('\n');
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    out
}

/// The four arrays of a shaped agent's field, as for a disc's: `V`, `W = 1 − V`, `log10 W` and
/// the mask, each `[nx, ny, headings]`.
pub fn pose_arrays(field: &PoseField) -> [Vec<u8>; 4] {
    let d = field.dims();
    let cells = (0..d.nx)
        .flat_map(move |i| (0..d.ny).flat_map(move |j| (0..d.nt).map(move |k| d.index(i, j, k))));
    four_arrays(
        (&field.w, &field.mask.blocked, &field.reachable),
        &[d.nx, d.ny, d.nt],
        cells,
    )
}

/// `V`, `W`, `log10 W` and the mask of a field of `shape`, its cells' indices taken in the
/// arrays' C order from `cells`.
fn four_arrays(
    (w, blocked, reachable): (&ScaledW, &[bool], &[bool]),
    shape: &[usize],
    cells: impl Iterator<Item = usize> + Clone,
) -> [Vec<u8>; 4] {
    let value = |c: usize| if reachable[c] { w.value(c) } else { 0.0 };
    let log = |c: usize| {
        if reachable[c] {
            w.log10(c)
        } else {
            f64::NEG_INFINITY
        }
    };
    let f8 =
        |f: &dyn Fn(usize) -> f64| npy_of(shape, "<f8", cells.clone().map(|c| f(c).to_le_bytes()));
    [
        f8(&|c| 1.0 - value(c)),
        f8(&value),
        f8(&log),
        npy_of(
            shape,
            "|u1",
            cells
                .clone()
                .map(|c| [CellClass::of(blocked[c], reachable[c]) as u8]),
        ),
    ]
}

/// The four arrays of an arm's joint-space field, as for a disc's: `V`, `W = 1 − V`, `log10 W`
/// and the mask, each with one axis per joint.
///
/// ```
/// use nadf::field::{JointAxis, JointField, JointMask, JointTarget, export};
/// use nadf::world::{Chain, Link};
/// let link = |length: f64| Link::rod(length, 1.0, 0.05);
/// let chain = Chain { base: [2.0, 2.0], links: vec![link(1.0), link(0.8)] };
/// let axis = JointAxis { cells: 16, limits: None };
/// let mask = JointMask::build(&chain, &[axis, axis], &[], ([0.0, 0.0], [4.0, 4.0]));
/// let target = JointTarget::Joints { q: vec![0.5, 1.0], radius: 0.4 };
/// let field = JointField::solve(&chain, mask, (&[-2.0, -1.0], &target), 1e-8, "arm").unwrap();
/// let [v, ..] = export::joint_arrays(&field);
/// assert!(String::from_utf8_lossy(&v[..128]).contains("'shape': (16, 16)"));
/// ```
pub fn joint_arrays(field: &JointField) -> [Vec<u8>; 4] {
    // The mask's index is C order over the joints' cells, the last joint fastest.
    let shape: Vec<usize> = field.mask.axes.iter().map(|a| a.cells).collect();
    four_arrays(
        (&field.w, &field.mask.blocked, &field.reachable),
        &shape,
        0..field.mask.blocked.len(),
    )
}

/// The four arrays of a disc's field that `nadf field --npy` writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FieldArray {
    /// `V = 1 − W` per cell as little-endian float64 (exactly 1 where `W` is below 1e-16).
    Potential,
    /// `W = 1 − V` per cell as little-endian float64, with full relative precision down to
    /// f64's range (0 below 1e-308: see [`FieldArray::Log10OneMinusPotential`]).
    OneMinusPotential,
    /// `log10 W` per cell as little-endian float64, at any depth (−inf on blocked and
    /// unreachable cells).
    Log10OneMinusPotential,
    /// The mask as uint8: one [`CellClass`] per cell.
    Mask,
}

impl FieldArray {
    /// The four arrays, in the order of the paths [`npy_paths`] gives them.
    pub const ALL: [Self; 4] = [
        Self::Potential,
        Self::OneMinusPotential,
        Self::Log10OneMinusPotential,
        Self::Mask,
    ];
}

/// Writes `array` of `field` to `out` as an `.npy` file of shape `[nx, ny]`, a few columns at a
/// time (a file is never held whole).
///
/// ```
/// # let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("worlds/room-two-dividers.toml");
/// # let world = nadf::world::load(&path, &["field.cell=0.1".parse().unwrap()]).unwrap();
/// use nadf::field::export::{FieldArray, write_array};
/// let field = nadf::field::HarmonicField::solve(&world, &world.agents[0]).unwrap();
/// let mut out = Vec::new();
/// write_array(&field, FieldArray::Mask, &mut out).unwrap();
/// assert_eq!(out.len(), 128 + field.grid().len());
/// ```
pub fn write_array(
    field: &HarmonicField,
    array: FieldArray,
    out: &mut dyn Write,
) -> std::io::Result<()> {
    let (grid, w) = (field.grid(), field.sampler.values());
    match array {
        FieldArray::Potential => write_npy(out, grid, "<f8", |k| (1.0 - w.value(k)).to_le_bytes()),
        FieldArray::OneMinusPotential => write_npy(out, grid, "<f8", |k| w.value(k).to_le_bytes()),
        FieldArray::Log10OneMinusPotential => {
            write_npy(out, grid, "<f8", |k| w.log10(k).to_le_bytes())
        }
        FieldArray::Mask => {
            let reachable = field.sampler.reachable_cells();
            write_npy(out, grid, "|u1", |k| {
                [CellClass::of(field.blocked[k], reachable[k]) as u8]
            })
        }
    }
}

/// [`FieldArray::Potential`] of `field`, in memory.
pub fn potential_npy(field: &HarmonicField) -> Vec<u8> {
    in_memory(|out| write_array(field, FieldArray::Potential, out))
}

/// [`FieldArray::OneMinusPotential`] of `field`, in memory.
pub fn one_minus_potential_npy(field: &HarmonicField) -> Vec<u8> {
    in_memory(|out| write_array(field, FieldArray::OneMinusPotential, out))
}

/// [`FieldArray::Log10OneMinusPotential`] of `field`, in memory.
pub fn log10_one_minus_potential_npy(field: &HarmonicField) -> Vec<u8> {
    in_memory(|out| write_array(field, FieldArray::Log10OneMinusPotential, out))
}

/// [`FieldArray::Mask`] of `field`, in memory.
pub fn mask_npy(field: &HarmonicField) -> Vec<u8> {
    in_memory(|out| write_array(field, FieldArray::Mask, out))
}

/// The paths of the four arrays `--npy FILE` writes: `FILE` (V), `FILE.w.npy`,
/// `FILE.log10w.npy` and `FILE.mask.npy` with `FILE`'s `.npy` extension replaced.
pub fn npy_paths(path: &std::path::Path) -> [std::path::PathBuf; 4] {
    let stem = path.with_extension("");
    let with = |suffix: &str| {
        let mut s = stem.as_os_str().to_owned();
        s.push(suffix);
        std::path::PathBuf::from(s)
    };
    [
        path.to_path_buf(),
        with(".w.npy"),
        with(".log10w.npy"),
        with(".mask.npy"),
    ]
}

/// Encodes RGB bytes (`width × height`, top row first) as a PNG.
pub fn png(rgb: &[u8], width: u32, height: u32) -> Vec<u8> {
    let mut out = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut out, width, height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().expect("writing to memory");
        writer.write_image_data(rgb).expect("writing to memory");
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn npy_headers_are_aligned_and_the_data_is_x_major() {
        let grid = Grid::covering([0.3, 0.2], 0.1);
        let bytes = in_memory(|out| write_npy(out, &grid, "|u1", |k| [k as u8]));
        assert_eq!(&bytes[..8], b"\x93NUMPY\x01\x00");
        let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
        assert_eq!((10 + header_len) % 64, 0);
        let header = std::str::from_utf8(&bytes[10..10 + header_len]).unwrap();
        assert!(
            header.contains("'shape': (3, 2)") && header.ends_with('\n'),
            "{header}"
        );
        // [i, j] order: (0,0), (0,1), (1,0), … with k = j·nx + i.
        assert_eq!(&bytes[10 + header_len..], &[0, 3, 1, 4, 2, 5]);
    }

    /// Columns beyond a tile's, elements of several bytes: the array is still x-major, element
    /// by element.
    #[test]
    fn tiles_keep_the_arrays_order() {
        let grid = Grid {
            nx: 2 * TILE + 5,
            ny: 7,
            cell: 1.0,
            origin: [0.0, 0.0],
        };
        let bytes = in_memory(|out| write_npy(out, &grid, "<u2", |k| (k as u16).to_le_bytes()));
        let data = &bytes[bytes.len() - 2 * grid.len()..];
        let expected: Vec<u8> = (0..grid.nx)
            .flat_map(|i| (0..grid.ny).map(move |j| j * grid.nx + i))
            .flat_map(|k| (k as u16).to_le_bytes())
            .collect();
        assert_eq!(data, &expected[..]);
    }

    #[test]
    fn npy_paths_put_the_extra_arrays_beside_the_first() {
        let [v, w, log, m] = npy_paths(std::path::Path::new("out/field.npy"));
        assert_eq!(v, std::path::Path::new("out/field.npy"));
        assert_eq!(w, std::path::Path::new("out/field.w.npy"));
        assert_eq!(log, std::path::Path::new("out/field.log10w.npy"));
        assert_eq!(m, std::path::Path::new("out/field.mask.npy"));
    }

    #[test]
    fn png_round_trips() {
        let rgb: Vec<u8> = (0..2 * 3 * 3).map(|v| v as u8 * 10).collect();
        let bytes = png(&rgb, 2, 3);
        let mut reader = png::Decoder::new(std::io::Cursor::new(bytes))
            .read_info()
            .unwrap();
        let mut out = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut out).unwrap();
        assert_eq!((info.width, info.height), (2, 3));
        assert_eq!(&out[..info.buffer_size()], &rgb[..]);
    }
}
