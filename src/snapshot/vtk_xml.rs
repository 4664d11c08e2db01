//! VTK's XML file formats, the ones ParaView and VTK's own readers open: particles as an unstructured grid of
//! vertices (`.vtu`), a gas grid as image data with cell data (`.vti`), and the time-series index (`.pvd`, a
//! "Collection" ParaView opens as one dataset over time).
//!
//! Every array is appended after the XML header as raw little-endian binary (`<AppendedData encoding="raw">`, each
//! block preceded by its byte count as a UInt64: `header_type="UInt64"`), the most compact of the format's
//! encodings and the fastest to read. The format is a few dozen lines of XML around the arrays (VTK's "VTK File
//! Formats" document, XML section), so it is written here rather than through a crate.

use std::fmt::Write as _;

/// One named data array: its VTK type, components per tuple and little-endian bytes.
#[derive(Debug, Clone, PartialEq)]
pub struct DataArray {
    pub name: String,
    vtk_type: &'static str,
    pub components: usize,
    bytes: Vec<u8>,
}

impl DataArray {
    /// Float64 values, `components` per tuple (3 for a vector).
    pub fn f64(name: &str, components: usize, values: impl IntoIterator<Item = f64>) -> Self {
        let bytes = values.into_iter().flat_map(f64::to_le_bytes).collect();
        DataArray {
            name: name.to_string(),
            vtk_type: "Float64",
            components,
            bytes,
        }
    }

    /// Int64 values, one per tuple.
    pub fn i64(name: &str, values: impl IntoIterator<Item = i64>) -> Self {
        let bytes = values.into_iter().flat_map(i64::to_le_bytes).collect();
        DataArray {
            name: name.to_string(),
            vtk_type: "Int64",
            components: 1,
            bytes,
        }
    }

    /// UInt8 values, one per tuple.
    pub fn u8(name: &str, values: impl IntoIterator<Item = u8>) -> Self {
        DataArray {
            name: name.to_string(),
            vtk_type: "UInt8",
            components: 1,
            bytes: values.into_iter().collect(),
        }
    }

    fn element_bytes(&self) -> usize {
        match self.vtk_type {
            "UInt8" => 1,
            _ => 8,
        }
    }

    /// Tuples held.
    pub fn tuples(&self) -> usize {
        self.bytes.len() / (self.element_bytes() * self.components.max(1))
    }
}

/// The XML header's array declarations and the appended blob, with each array's offset into it.
struct Appended {
    blob: Vec<u8>,
}

impl Appended {
    fn new() -> Self {
        Appended { blob: Vec::new() }
    }

    /// Declares `array` (written with the given name, `None` for none) and appends its block.
    fn declare(&mut self, xml: &mut String, indent: &str, array: &DataArray, name: Option<&str>) {
        let offset = self.blob.len();
        self.blob.extend_from_slice(&(array.bytes.len() as u64).to_le_bytes());
        self.blob.extend_from_slice(&array.bytes);
        let name = name.map(|n| format!(" Name=\"{}\"", escape(n))).unwrap_or_default();
        let _ = writeln!(
            xml,
            "{indent}<DataArray type=\"{}\"{name} NumberOfComponents=\"{}\" NumberOfTuples=\"{}\" \
             format=\"appended\" offset=\"{offset}\"/>",
            array.vtk_type,
            array.components,
            array.tuples()
        );
    }

    /// The XML text, the appended blob and the closing tags: the whole file.
    fn finish(self, mut xml: String) -> Vec<u8> {
        xml.push_str("  <AppendedData encoding=\"raw\">\n   _");
        let mut bytes = xml.into_bytes();
        bytes.extend_from_slice(&self.blob);
        bytes.extend_from_slice(b"\n  </AppendedData>\n</VTKFile>\n");
        bytes
    }
}

fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('"', "&quot;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

fn header(kind: &str) -> String {
    format!(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"{kind}\" version=\"1.0\" byte_order=\"LittleEndian\" \
         header_type=\"UInt64\">\n"
    )
}

/// The time of a dataset as ParaView reads it from field data (`TimeValue`).
fn field_data(xml: &mut String, appended: &mut Appended, time_s: f64) {
    xml.push_str("    <FieldData>\n");
    appended.declare(
        xml,
        "      ",
        &DataArray::f64("TimeValue", 1, [time_s]),
        Some("TimeValue"),
    );
    xml.push_str("    </FieldData>\n");
}

/// A `.vtu` of `points` (one VTK_VERTEX cell each) carrying `point_data` (one tuple per point), at `time_s`.
pub fn points_file(points: &[[f64; 3]], point_data: &[DataArray], time_s: f64) -> Vec<u8> {
    let n = points.len();
    let mut xml = header("UnstructuredGrid");
    let mut appended = Appended::new();
    xml.push_str("  <UnstructuredGrid>\n");
    field_data(&mut xml, &mut appended, time_s);
    let _ = writeln!(xml, "    <Piece NumberOfPoints=\"{n}\" NumberOfCells=\"{n}\">");
    xml.push_str("      <PointData>\n");
    for array in point_data {
        debug_assert_eq!(array.tuples(), n, "{}", array.name);
        appended.declare(&mut xml, "        ", array, Some(&array.name));
    }
    xml.push_str("      </PointData>\n      <Points>\n");
    appended.declare(
        &mut xml,
        "        ",
        &DataArray::f64("Points", 3, points.iter().flatten().copied()),
        None,
    );
    xml.push_str("      </Points>\n      <Cells>\n");
    const VTK_VERTEX: u8 = 1;
    appended.declare(
        &mut xml,
        "        ",
        &DataArray::i64("connectivity", 0..n as i64),
        Some("connectivity"),
    );
    appended.declare(
        &mut xml,
        "        ",
        &DataArray::i64("offsets", 1..=n as i64),
        Some("offsets"),
    );
    appended.declare(
        &mut xml,
        "        ",
        &DataArray::u8("types", std::iter::repeat_n(VTK_VERTEX, n)),
        Some("types"),
    );
    xml.push_str("      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n");
    appended.finish(xml)
}

/// A `.vti` of a regular grid of `cells` (x fastest, then y, then z) from `origin_m` with cell size `spacing_m`,
/// carrying `cell_data` (one tuple per cell), at `time_s`.
pub fn grid_file(
    origin_m: [f64; 3],
    spacing_m: [f64; 3],
    cells: [usize; 3],
    cell_data: &[DataArray],
    time_s: f64,
) -> Vec<u8> {
    let extent = format!("0 {} 0 {} 0 {}", cells[0], cells[1], cells[2]);
    let mut xml = header("ImageData");
    let mut appended = Appended::new();
    let _ = writeln!(
        xml,
        "  <ImageData WholeExtent=\"{extent}\" Origin=\"{:e} {:e} {:e}\" Spacing=\"{:e} {:e} {:e}\">",
        origin_m[0], origin_m[1], origin_m[2], spacing_m[0], spacing_m[1], spacing_m[2]
    );
    field_data(&mut xml, &mut appended, time_s);
    let _ = writeln!(xml, "    <Piece Extent=\"{extent}\">");
    xml.push_str("      <CellData>\n");
    for array in cell_data {
        debug_assert_eq!(array.tuples(), cells.iter().product::<usize>(), "{}", array.name);
        appended.declare(&mut xml, "        ", array, Some(&array.name));
    }
    xml.push_str("      </CellData>\n    </Piece>\n  </ImageData>\n");
    appended.finish(xml)
}

/// A `.pvd` listing `(time, file name)` datasets in order: ParaView opens it as one dataset over time.
pub fn collection_file(entries: &[(f64, String)]) -> String {
    let mut xml = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  \
         <Collection>\n",
    );
    for (time_s, file) in entries {
        // {:e} of an f64 is the shortest text that reads back as the same number.
        let _ = writeln!(
            xml,
            "    <DataSet timestep=\"{time_s:e}\" group=\"\" part=\"0\" file=\"{}\"/>",
            escape(file)
        );
    }
    xml.push_str("  </Collection>\n</VTKFile>\n");
    xml
}

/// The `(time, file name)` entries of a `.pvd` this module wrote (its own one-dataset-per-line layout); lines it
/// does not recognise are skipped.
pub fn read_collection(text: &str) -> Vec<(f64, String)> {
    let attribute = |line: &str, key: &str| -> Option<String> {
        let start = line.find(&format!(" {key}=\""))? + key.len() + 3;
        let end = start + line[start..].find('"')?;
        Some(
            line[start..end]
                .replace("&quot;", "\"")
                .replace("&lt;", "<")
                .replace("&gt;", ">")
                .replace("&amp;", "&"),
        )
    };
    text.lines()
        .filter(|line| line.trim_start().starts_with("<DataSet "))
        .filter_map(|line| {
            let time_s = attribute(line, "timestep")?.parse().ok()?;
            Some((time_s, attribute(line, "file")?))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_collection_reads_back_as_written() {
        let entries = vec![
            (0.0, "particles_000000000000.vtu".to_string()),
            (0.1 + 0.2, "a&b\".vtu".into()),
        ];
        assert_eq!(read_collection(&collection_file(&entries)), entries);
    }

    #[test]
    fn appended_blocks_carry_their_byte_counts_at_their_offsets() {
        let file = points_file(
            &[[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]],
            &[DataArray::f64("radius_m", 1, [0.5, 0.25])],
            0.0,
        );
        let marker = b"encoding=\"raw\">\n   _";
        let start = file.windows(marker.len()).position(|w| w == marker).unwrap() + marker.len();
        let text = String::from_utf8_lossy(&file[..start]);
        let offset: usize = text
            .split("Name=\"radius_m\"")
            .nth(1)
            .and_then(|s| s.split("offset=\"").nth(1))
            .and_then(|s| s.split('"').next())
            .unwrap()
            .parse()
            .unwrap();
        let block = &file[start + offset..];
        assert_eq!(u64::from_le_bytes(block[..8].try_into().unwrap()), 16);
        assert_eq!(f64::from_le_bytes(block[8..16].try_into().unwrap()), 0.5);
        assert_eq!(f64::from_le_bytes(block[16..24].try_into().unwrap()), 0.25);
    }
}
