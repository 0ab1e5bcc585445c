//! The RGL "tensor file": a binary container of named n-dimensional arrays,
//! the input of Mitsuba 3's `measured` BSDF (and of the RGL material
//! database's tools).
//!
//! Layout (all little-endian):
//! - 12 bytes `tensor_file\0`, 2 bytes version (1, 0), `u32` field count;
//! - per field: `u16` name length, the name (UTF-8, no terminator), `u16`
//!   number of dimensions, `u8` type (1 = `u8`, 10 = `f32`), `u64` byte
//!   offset of its data from the start of the file, then one `u64` per
//!   dimension (the shape, slowest first);
//! - the fields' data, row-major (last index fastest), each starting on a
//!   multiple of 8 bytes.

/// A field's values.
#[derive(Debug, Clone, PartialEq)]
pub enum Values {
    U8(Vec<u8>),
    F32(Vec<f32>),
}

impl Values {
    fn type_code(&self) -> u8 {
        match self {
            Values::U8(_) => 1,
            Values::F32(_) => 10,
        }
    }

    fn len(&self) -> usize {
        match self {
            Values::U8(v) => v.len(),
            Values::F32(v) => v.len(),
        }
    }

    fn bytes(&self) -> Vec<u8> {
        match self {
            Values::U8(v) => v.clone(),
            Values::F32(v) => v.iter().flat_map(|x| x.to_le_bytes()).collect(),
        }
    }
}

/// One named array.
#[derive(Debug, Clone, PartialEq)]
pub struct Field {
    pub name: String,
    pub shape: Vec<usize>,
    pub values: Values,
}

impl Field {
    /// A field; `None` where the shape does not hold exactly the values.
    pub fn new(name: &str, shape: &[usize], values: Values) -> Option<Field> {
        (shape.iter().product::<usize>() == values.len()).then(|| Field {
            name: name.to_string(),
            shape: shape.to_vec(),
            values,
        })
    }
}

const ALIGN: usize = 8;

fn aligned(n: usize) -> usize {
    n.div_ceil(ALIGN) * ALIGN
}

/// The tensor file holding `fields`, in their order.
pub fn encode(fields: &[Field]) -> Vec<u8> {
    let header_len: usize = 12
        + 2
        + 4
        + fields
            .iter()
            .map(|f| 2 + f.name.len() + 2 + 1 + 8 + 8 * f.shape.len())
            .sum::<usize>();
    let mut offsets = Vec::with_capacity(fields.len());
    let mut at = aligned(header_len);
    for f in fields {
        offsets.push(at);
        at = aligned(at + f.values.bytes().len());
    }
    let mut out = Vec::with_capacity(at);
    out.extend_from_slice(b"tensor_file\0");
    out.extend_from_slice(&[1, 0]);
    out.extend_from_slice(&(fields.len() as u32).to_le_bytes());
    for (f, &off) in fields.iter().zip(&offsets) {
        out.extend_from_slice(&(f.name.len() as u16).to_le_bytes());
        out.extend_from_slice(f.name.as_bytes());
        out.extend_from_slice(&(f.shape.len() as u16).to_le_bytes());
        out.push(f.values.type_code());
        out.extend_from_slice(&(off as u64).to_le_bytes());
        for &d in &f.shape {
            out.extend_from_slice(&(d as u64).to_le_bytes());
        }
    }
    for (f, &off) in fields.iter().zip(&offsets) {
        out.resize(off, 0);
        out.extend_from_slice(&f.values.bytes());
    }
    out.resize(at, 0);
    out
}
