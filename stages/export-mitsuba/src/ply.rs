//! Binary little-endian PLY (Stanford triangle format) as Mitsuba 3's `ply`
//! shape reads it: `element vertex` with `float x, y, z`, `element face`
//! with `property list uchar int vertex_indices`.

/// The PLY file of `positions` (mesh frame, m) and triangles `faces`
/// (indices into `positions`, counter-clockwise seen from the front), with
/// `note` as a header comment (line breaks become spaces).
pub fn encode(positions: &[[f32; 3]], faces: &[[u32; 3]], note: &str) -> Vec<u8> {
    let note: String = note.chars().map(|c| if c.is_control() { ' ' } else { c }).collect();
    let header = format!(
        "ply\nformat binary_little_endian 1.0\ncomment {note}\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        positions.len(),
        faces.len()
    );
    let mut bytes = Vec::with_capacity(header.len() + 12 * positions.len() + 13 * faces.len());
    bytes.extend_from_slice(header.as_bytes());
    for p in positions {
        for c in p {
            bytes.extend_from_slice(&c.to_le_bytes());
        }
    }
    for f in faces {
        bytes.push(3);
        for &i in f {
            bytes.extend_from_slice(&(i as i32).to_le_bytes());
        }
    }
    bytes
}

/// A PLY file's positions and faces.
pub type Decoded = (Vec<[f32; 3]>, Vec<[u32; 3]>);

/// Reads back a file [`encode`] wrote: positions and faces, or what is
/// wrong with it.
pub fn decode(bytes: &[u8]) -> Result<Decoded, String> {
    const END: &[u8] = b"end_header\n";
    let end = bytes.windows(END.len()).position(|w| w == END).ok_or("no end_header")? + END.len();
    let header = std::str::from_utf8(&bytes[..end]).map_err(|e| e.to_string())?;
    if !header.starts_with("ply\nformat binary_little_endian 1.0\n") {
        return Err("not a binary little-endian PLY".into());
    }
    let count = |element: &str| -> Result<usize, String> {
        header
            .lines()
            .find_map(|l| l.strip_prefix(&format!("element {element} ")))
            .ok_or(format!("no element {element}"))?
            .parse()
            .map_err(|e| format!("element {element}: {e}"))
    };
    let (nv, nf) = (count("vertex")?, count("face")?);
    let body = &bytes[end..];
    if body.len() != 12 * nv + 13 * nf {
        return Err(format!("body has {} bytes, expected {}", body.len(), 12 * nv + 13 * nf));
    }
    let f32_at = |o: usize| f32::from_le_bytes(body[o..o + 4].try_into().unwrap());
    let positions = (0..nv).map(|i| [f32_at(12 * i), f32_at(12 * i + 4), f32_at(12 * i + 8)]).collect();
    let mut faces = Vec::with_capacity(nf);
    for i in 0..nf {
        let o = 12 * nv + 13 * i;
        if body[o] != 3 {
            return Err(format!("face {i} has {} vertices", body[o]));
        }
        let at = |k: usize| i32::from_le_bytes(body[o + 1 + 4 * k..o + 5 + 4 * k].try_into().unwrap());
        let face = [at(0), at(1), at(2)];
        if face.iter().any(|&v| v < 0 || v as usize >= nv) {
            return Err(format!("face {i} indexes a vertex out of range"));
        }
        faces.push(face.map(|v| v as u32));
    }
    Ok((positions, faces))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip() {
        let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, -2.5]];
        let faces = [[0, 1, 2], [2, 1, 0]];
        let bytes = encode(&positions, &faces, "two\nfaces");
        assert!(bytes.starts_with(b"ply\nformat binary_little_endian 1.0\ncomment two faces\n"));
        assert_eq!(decode(&bytes).unwrap(), (positions.to_vec(), faces.to_vec()));
        assert!(decode(&bytes[..bytes.len() - 1]).is_err());
    }
}
