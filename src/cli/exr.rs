//! OpenEXR, the little of it scnc needs: a single-part scanline image of linear float
//! RGB, written uncompressed, and read back (uncompressed, FLOAT or HALF channels) for
//! `scnc sweep --reference`. Hand-written rather than through the `image` crate's codec,
//! whose `exr` dependency (with `pulp` and its kin) added minutes to every clean build
//! for these few hundred bytes of header.
//!
//! The layout (OpenEXR's "Technical Introduction", "OpenEXR File Layout"): the magic
//! number and version, attributes (`name\0type\0size value`) ending in a zero byte, a
//! table of each scanline's offset, then per scanline its `y`, its byte count and its
//! channels one after another, in the channel list's alphabetical order (B, G, R).

const MAGIC: [u8; 4] = [0x76, 0x2f, 0x31, 0x01];
/// Version 2, single-part scanline, short names.
const VERSION: [u8; 4] = [2, 0, 0, 0];
const FLOAT: i32 = 2;
const HALF: i32 = 1;

/// Encodes `rgb` (`width × height × 3` linear floats, rows top to bottom) as an
/// uncompressed OpenEXR file.
pub(crate) fn encode(width: u32, height: u32, rgb: &[f32]) -> Vec<u8> {
    let mut out = Vec::with_capacity(400 + rgb.len() * 4 + height as usize * 16);
    out.extend(MAGIC);
    out.extend(VERSION);
    let attribute = |out: &mut Vec<u8>, name: &str, ty: &str, value: &[u8]| {
        out.extend(name.as_bytes());
        out.push(0);
        out.extend(ty.as_bytes());
        out.push(0);
        out.extend((value.len() as i32).to_le_bytes());
        out.extend(value);
    };
    let mut channels = Vec::new();
    for name in ["B", "G", "R"] {
        channels.extend(name.as_bytes());
        channels.push(0);
        channels.extend(FLOAT.to_le_bytes());
        channels.extend([0u8; 4]); // pLinear and three reserved bytes
        channels.extend(1i32.to_le_bytes());
        channels.extend(1i32.to_le_bytes());
    }
    channels.push(0);
    let window: Vec<u8> = [0i32, 0, width as i32 - 1, height as i32 - 1].iter().flat_map(|v| v.to_le_bytes()).collect();
    attribute(&mut out, "channels", "chlist", &channels);
    attribute(&mut out, "compression", "compression", &[0]);
    attribute(&mut out, "dataWindow", "box2i", &window);
    attribute(&mut out, "displayWindow", "box2i", &window);
    attribute(&mut out, "lineOrder", "lineOrder", &[0]);
    attribute(&mut out, "pixelAspectRatio", "float", &1f32.to_le_bytes());
    attribute(&mut out, "screenWindowCenter", "v2f", &[0u8; 8]);
    attribute(&mut out, "screenWindowWidth", "float", &1f32.to_le_bytes());
    out.push(0);
    let (w, h) = (width as usize, height as usize);
    let line_bytes = 8 + 3 * 4 * w;
    let table_end = out.len() + 8 * h;
    for y in 0..h {
        out.extend(((table_end + y * line_bytes) as u64).to_le_bytes());
    }
    for y in 0..h {
        out.extend((y as i32).to_le_bytes());
        out.extend(((3 * 4 * w) as i32).to_le_bytes());
        let row = &rgb[3 * w * y..3 * w * (y + 1)];
        for channel in [2, 1, 0] {
            for x in 0..w {
                out.extend(row[3 * x + channel].to_le_bytes());
            }
        }
    }
    out
}

/// A reader over a file's bytes that fails instead of running past the end.
struct Bytes<'a> {
    data: &'a [u8],
    at: usize,
}

impl<'a> Bytes<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.data.len()).ok_or("the file ends early")?;
        let s = &self.data[self.at..end];
        self.at = end;
        Ok(s)
    }

    fn i32(&mut self) -> Result<i32, String> {
        Ok(i32::from_le_bytes(self.take(4)?.try_into().map_err(|_| "a short number")?))
    }

    fn name(&mut self) -> Result<&'a str, String> {
        let rest = &self.data[self.at..];
        let n = rest.iter().take(256).position(|&b| b == 0).ok_or("a name without its end")?;
        let s = std::str::from_utf8(&rest[..n]).map_err(|_| "a name that is not text")?;
        self.at += n + 1;
        Ok(s)
    }
}

/// A HALF (IEEE binary16) as an f32.
fn half(bits: u16) -> f32 {
    let sign = if bits & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exp = i32::from((bits >> 10) & 0x1f);
    let frac = f32::from(bits & 0x3ff);
    sign * match exp {
        0 => frac * 2f32.powi(-24),
        31 if frac == 0.0 => f32::INFINITY,
        31 => f32::NAN,
        e => (1.0 + frac / 1024.0) * 2f32.powi(e - 15),
    }
}

/// Reads an uncompressed single-part scanline OpenEXR file with R, G and B channels
/// (FLOAT or HALF): its size and its values as `rgb` rows top to bottom. Anything else
/// (compression, tiles, other channel types) is an error saying what it is.
pub(crate) fn decode(data: &[u8], max_pixels: u64) -> Result<(u32, u32, Vec<f32>), String> {
    let mut r = Bytes { data, at: 0 };
    if r.take(4)? != MAGIC {
        return Err("not an OpenEXR file".into());
    }
    let version = r.take(4)?;
    if version[0] != 2 || version[1] & 0x1a != 0 {
        return Err("an OpenEXR file that is tiled, deep or multi-part: scnc reads single-part scanline images".into());
    }
    let (mut channels, mut compression, mut window) = (Vec::new(), None, None);
    loop {
        let name = r.name()?;
        if name.is_empty() {
            break;
        }
        let ty = r.name()?;
        let size = usize::try_from(r.i32()?).map_err(|_| "a negative attribute size")?;
        let value = r.take(size)?;
        match (name, ty) {
            ("channels", "chlist") => {
                let mut c = Bytes { data: value, at: 0 };
                loop {
                    let n = c.name()?;
                    if n.is_empty() {
                        break;
                    }
                    let t = c.i32()?;
                    c.take(12)?;
                    channels.push((n.to_string(), t));
                }
            }
            ("compression", "compression") => compression = value.first().copied(),
            ("dataWindow", "box2i") if size == 16 => {
                let v: Vec<i32> = value.chunks_exact(4).map(|b| i32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
                window = Some((v[0], v[1], v[2], v[3]));
            }
            _ => {}
        }
    }
    if compression != Some(0) {
        return Err("a compressed OpenEXR file: scnc reads uncompressed ones (as `scnc render -o x.exr` writes)".into());
    }
    let (x0, y0, x1, y1) = window.ok_or("no data window")?;
    let (w, h) = (i64::from(x1) - i64::from(x0) + 1, i64::from(y1) - i64::from(y0) + 1);
    if w <= 0 || h <= 0 || (w * h) as u64 > max_pixels {
        return Err(format!("an image of {w}×{h} pixels"));
    }
    let (w, h) = (w as usize, h as usize);
    for (_, t) in &channels {
        if *t != FLOAT && *t != HALF {
            return Err("a channel that is neither FLOAT nor HALF".into());
        }
    }
    let slot = |name: &str| channels.iter().position(|(n, _)| n == name);
    let (Some(ri), Some(gi), Some(bi)) = (slot("R"), slot("G"), slot("B")) else {
        return Err("an image without R, G and B channels".into());
    };
    r.take(8 * h)?; // the offset table: the lines follow it in order
    let mut rgb = vec![0f32; w * h * 3];
    for _ in 0..h {
        let y = i64::from(r.i32()?) - i64::from(y0);
        let _size = r.i32()?;
        let y = usize::try_from(y).ok().filter(|&y| y < h).ok_or("a line outside the image")?;
        for (k, (_, t)) in channels.iter().enumerate() {
            let out = [(ri, 0), (gi, 1), (bi, 2)].iter().find(|(i, _)| *i == k).map(|&(_, c)| c);
            for x in 0..w {
                let v = if *t == FLOAT {
                    f32::from_le_bytes(r.take(4)?.try_into().map_err(|_| "a short value")?)
                } else {
                    half(u16::from_le_bytes(r.take(2)?.try_into().map_err(|_| "a short value")?))
                };
                if let Some(c) = out {
                    rgb[3 * (w * y + x) + c] = v;
                }
            }
        }
    }
    Ok((w as u32, h as u32, rgb))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_image_survives_its_round_trip() {
        let rgb: Vec<f32> = (0..5 * 3 * 3).map(|i| i as f32 * 0.25 - 1.0).collect();
        let bytes = encode(5, 3, &rgb);
        assert_eq!(decode(&bytes, 100), Ok((5, 3, rgb)));
        assert!(decode(&bytes[..bytes.len() - 1], 100).is_err());
        assert!(decode(&bytes, 14).is_err());
    }

    #[test]
    fn halves_are_read_exactly() {
        assert_eq!(half(0x3c00), 1.0);
        assert_eq!(half(0xc000), -2.0);
        assert_eq!(half(0x0001), 2f32.powi(-24));
        assert!(half(0x7c00).is_infinite());
    }
}
