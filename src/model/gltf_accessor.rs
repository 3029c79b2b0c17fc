//! glTF accessors read as numbers: every component type, normalized or not (so the quantized
//! positions of `KHR_mesh_quantization`), strided views, and sparse substitution.
//!
//! Owns the byte-level reading of an accessor; every read is bounds-checked against its view and
//! buffer, so a hostile file gives an error, never a panic.

use ::gltf::accessor::{DataType, Dimensions};

/// Largest element count of an accessor that has no buffer view (all zeros, then sparse
/// substitutions): such an accessor costs memory without bytes in the file to back it.
const MAX_VIEWLESS_COUNT: usize = 1 << 24;

/// The accessor's components, `count × dimensions` of them, as numbers: integers as they are, or
/// mapped to [−1, 1] / [0, 1] when `normalized` (glTF 2.0 §3.11), with sparse values substituted.
pub fn read_values(acc: &::gltf::Accessor, buffers: &[Vec<u8>]) -> Result<Vec<f64>, String> {
    let dims = acc.dimensions().multiplicity();
    let format = Format { data_type: acc.data_type(), normalized: acc.normalized() };
    let elem = dims * format.size();
    let mut out = match acc.view() {
        Some(_) => {
            let (bytes, stride) = accessor_bytes(acc, buffers, elem)?;
            let mut values = Vec::with_capacity(acc.count() * dims);
            for i in 0..acc.count() {
                format.decode_into(&bytes[i * stride..i * stride + elem], &mut values);
            }
            values
        }
        None if acc.count() > MAX_VIEWLESS_COUNT => {
            return Err(format!(
                "accessor {} has no buffer view and {} elements (at most {MAX_VIEWLESS_COUNT} are read from sparse data alone)",
                acc.index(),
                acc.count()
            ));
        }
        None => vec![0.0; acc.count() * dims],
    };
    if let Some(sparse) = acc.sparse() {
        apply_sparse(acc.index(), &sparse, buffers, format, dims, &mut out)?;
    }
    Ok(out)
}

/// Positions as f32 triples: float, or (normalized) byte/short as `KHR_mesh_quantization` allows.
pub fn read_positions(acc: &::gltf::Accessor, buffers: &[Vec<u8>]) -> Result<Vec<[f32; 3]>, String> {
    if acc.dimensions() != Dimensions::Vec3 || acc.data_type() == DataType::U32 {
        return Err(format!(
            "POSITION accessor {} is {:?} of {:?}; expected VEC3 of float, or of (normalized) byte or short (KHR_mesh_quantization)",
            acc.index(),
            acc.dimensions(),
            acc.data_type()
        ));
    }
    let values = read_values(acc, buffers)?;
    Ok(values.chunks_exact(3).map(|p| [p[0] as f32, p[1] as f32, p[2] as f32]).collect())
}

/// Triangle (or strip, fan) indices: a SCALAR accessor of unsigned bytes, shorts or ints.
pub fn read_indices(acc: &::gltf::Accessor, buffers: &[Vec<u8>]) -> Result<Vec<u32>, String> {
    if !matches!(acc.data_type(), DataType::U8 | DataType::U16 | DataType::U32) {
        return Err(format!("index accessor {} has type {:?}; expected an unsigned integer", acc.index(), acc.data_type()));
    }
    if acc.dimensions() != Dimensions::Scalar {
        return Err(format!("index accessor {} is not SCALAR", acc.index()));
    }
    if acc.normalized() {
        return Err(format!("index accessor {} is normalized; indices must not be", acc.index()));
    }
    // Unsigned integers up to 2³² − 1 are exact in f64.
    Ok(read_values(acc, buffers)?.into_iter().map(|v| v as u32).collect())
}

/// The bytes of an accessor's elements, bounds-checked against its view and buffer.
fn accessor_bytes<'a>(acc: &::gltf::Accessor, buffers: &'a [Vec<u8>], elem: usize) -> Result<(&'a [u8], usize), String> {
    let view = acc.view().ok_or_else(|| format!("accessor {} has no buffer view", acc.index()))?;
    let buffer = buffers.get(view.buffer().index()).ok_or_else(|| format!("buffer {} is missing", view.buffer().index()))?;
    let stride = view.stride().unwrap_or(elem);
    if stride < elem {
        return Err(format!("accessor {}: its view's byteStride {stride} is less than an element ({elem} bytes)", acc.index()));
    }
    let start = view.offset().checked_add(acc.offset()).ok_or("offset overflow")?;
    let view_end = view.offset().checked_add(view.length()).ok_or("offset overflow")?;
    let bytes = span(buffer, start, view_end, acc.count(), stride, elem).map_err(|end| match end {
        Some(end) => format!(
            "accessor {} reads bytes {start}..{end} beyond its buffer view (ends at {view_end}) or buffer ({} bytes)",
            acc.index(),
            buffer.len()
        ),
        None => "size overflow".to_string(),
    })?;
    Ok((bytes, stride))
}

/// `buffer[start..]` covering `count` elements of `elem` bytes every `stride` bytes, if it ends
/// within `limit` and the buffer; else the end it needs (`None`: past `usize`).
fn span(buffer: &[u8], start: usize, limit: usize, count: usize, stride: usize, elem: usize) -> Result<&[u8], Option<usize>> {
    let need = match count {
        0 => Some(0),
        n => stride.checked_mul(n - 1).and_then(|x| x.checked_add(elem)),
    };
    let end = need.and_then(|n| start.checked_add(n));
    match end {
        Some(end) if end <= limit && limit <= buffer.len() => Ok(&buffer[start..end]),
        _ => Err(end),
    }
}

/// Sparse storage (glTF 2.0 §3.6.2.3): `count` element indices and their replacement values.
fn apply_sparse(
    index: usize,
    sparse: &::gltf::accessor::sparse::Sparse,
    buffers: &[Vec<u8>],
    format: Format,
    dims: usize,
    out: &mut [f64],
) -> Result<(), String> {
    use ::gltf::accessor::sparse::IndexType;
    let count = sparse.count();
    let index_format = Format {
        data_type: match sparse.indices().index_type() {
            IndexType::U8 => DataType::U8,
            IndexType::U16 => DataType::U16,
            IndexType::U32 => DataType::U32,
        },
        normalized: false,
    };
    let bytes_of = |view: ::gltf::buffer::View, offset: usize, elem: usize, what: &str| {
        let buffer = buffers.get(view.buffer().index()).ok_or_else(|| format!("buffer {} is missing", view.buffer().index()))?;
        let start = view.offset().checked_add(offset).ok_or("offset overflow")?;
        let limit = view.offset().checked_add(view.length()).ok_or("offset overflow")?;
        span(buffer, start, limit, count, elem, elem).map_err(|end| match end {
            Some(end) => {
                format!("accessor {index}: sparse {what} read bytes {start}..{end} beyond their view or buffer ({} bytes)", buffer.len())
            }
            None => "size overflow".to_string(),
        })
    };
    let indices = bytes_of(sparse.indices().view(), sparse.indices().offset(), index_format.size(), "indices")?;
    let elem = dims * format.size();
    let values = bytes_of(sparse.values().view(), sparse.values().offset(), elem, "values")?;
    let elements = out.len() / dims.max(1);
    let mut position = Vec::with_capacity(1);
    let mut value = Vec::with_capacity(dims);
    for k in 0..count {
        position.clear();
        index_format.decode_into(&indices[k * index_format.size()..(k + 1) * index_format.size()], &mut position);
        let target = position[0] as usize;
        let range = target.checked_mul(dims).and_then(|a| Some(a..a.checked_add(dims)?));
        let slot = range
            .and_then(|r| out.get_mut(r))
            .ok_or_else(|| format!("accessor {index}: sparse index {target} is past its {elements} elements"))?;
        value.clear();
        format.decode_into(&values[k * elem..(k + 1) * elem], &mut value);
        slot.copy_from_slice(&value);
    }
    Ok(())
}

/// A component type and whether it is normalized.
#[derive(Debug, Clone, Copy)]
struct Format {
    data_type: DataType,
    normalized: bool,
}

impl Format {
    fn size(self) -> usize {
        match self.data_type {
            DataType::I8 | DataType::U8 => 1,
            DataType::I16 | DataType::U16 => 2,
            DataType::U32 | DataType::F32 => 4,
        }
    }

    /// Appends the components in `bytes` (a whole number of them, little-endian).
    fn decode_into(self, bytes: &[u8], out: &mut Vec<f64>) {
        let n = self.normalized;
        match self.data_type {
            DataType::I8 => out.extend(bytes.iter().map(|&b| signed(f64::from(b as i8), 127.0, n))),
            DataType::U8 => out.extend(bytes.iter().map(|&b| unsigned(f64::from(b), 255.0, n))),
            DataType::I16 => out.extend(bytes.chunks_exact(2).map(|c| signed(f64::from(i16::from_le_bytes([c[0], c[1]])), 32767.0, n))),
            DataType::U16 => out.extend(bytes.chunks_exact(2).map(|c| unsigned(f64::from(u16::from_le_bytes([c[0], c[1]])), 65535.0, n))),
            DataType::U32 => out
                .extend(bytes.chunks_exact(4).map(|c| unsigned(f64::from(u32::from_le_bytes([c[0], c[1], c[2], c[3]])), 4294967295.0, n))),
            DataType::F32 => out.extend(bytes.chunks_exact(4).map(|c| f64::from(f32::from_le_bytes([c[0], c[1], c[2], c[3]])))),
        }
    }
}

/// A signed integer component: normalized, `max(c / max, −1)` (glTF 2.0 §3.11).
fn signed(c: f64, max: f64, normalized: bool) -> f64 {
    if normalized { (c / max).max(-1.0) } else { c }
}

fn unsigned(c: f64, max: f64, normalized: bool) -> f64 {
    if normalized { c / max } else { c }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normalized_components_follow_the_gltf_rules() {
        let mut out = Vec::new();
        Format { data_type: DataType::I8, normalized: true }.decode_into(&[127, 0x81, 0x80], &mut out);
        assert_eq!(out, [1.0, -1.0, -1.0]);
        out.clear();
        Format { data_type: DataType::I16, normalized: true }.decode_into(&(-16384i16).to_le_bytes(), &mut out);
        assert_eq!(out, [-16384.0 / 32767.0]);
        out.clear();
        Format { data_type: DataType::U16, normalized: false }.decode_into(&65535u16.to_le_bytes(), &mut out);
        assert_eq!(out, [65535.0]);
        out.clear();
        Format { data_type: DataType::U8, normalized: true }.decode_into(&[51], &mut out);
        assert_eq!(out, [0.2]);
    }

    #[test]
    fn a_span_past_its_view_is_refused() {
        let buffer = [0u8; 16];
        assert_eq!(span(&buffer, 4, 16, 2, 6, 6).map(<[u8]>::len), Ok(12));
        assert!(span(&buffer, 4, 12, 2, 6, 6).is_err());
        assert!(span(&buffer, 4, 32, 2, 6, 6).is_err());
        assert!(span(&buffer, usize::MAX, 32, 2, 6, 6).is_err());
    }
}
