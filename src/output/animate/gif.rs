//! The animated GIF: frames drawn by [`super::render`], mapped to one fixed global palette,
//! and stored as the rectangle that changed since the previous frame (unchanged pixels
//! transparent), which keeps the files small.
//!
//! Timing: frame j is shown for (t_{j+1} − t_j) / speed seconds of real time, rounded to GIF's
//! centiseconds so that the rounding never accumulates (each frame ends at the centisecond
//! nearest to its end time), but at least 2 cs (browsers slow shorter delays down); the last
//! frame is held for [`LAST_FRAME_HOLD`] cs before the loop restarts.

use std::borrow::Cow;

use nalgebra::Vector3;

use crr_kinematics::shapes::Surface;

use super::render::{
    BACKGROUND, BASE_COLOURS, Face, GROUND_COLOUR, HEIGHT, OUTLINE, Renderer, SHADE_LEVELS, WIDTH,
    ground_slab, shade,
};
use super::{Ground, State};
use crate::Error;

/// Grey levels of the palette (white to black), for the text's anti-aliasing.
pub const GREYS: usize = 32;

/// The palette index left unused by the drawing and marking unchanged pixels.
pub const TRANSPARENT: u8 = 255;

/// The shortest frame delay written (centiseconds).
pub const MIN_DELAY: u16 = 2;

/// How long the last frame is held before the animation loops (centiseconds).
pub const LAST_FRAME_HOLD: u16 = 100;

/// The fixed global palette (RGB triples, 256 entries): the [`SHADE_LEVELS`] shades of every
/// base colour, [`GREYS`] greys from white to black, the outline colour, then black padding
/// (the last entry, [`TRANSPARENT`], is never drawn).
pub fn palette() -> Vec<[u8; 3]> {
    let mut p = Vec::with_capacity(256);
    for base in 0..BASE_COLOURS.len() {
        for level in 0..SHADE_LEVELS {
            p.push(shade(base, level));
        }
    }
    for g in 0..GREYS {
        let v = (255.0 * (1.0 - g as f64 / (GREYS - 1) as f64)).round() as u8;
        p.push([v; 3]);
    }
    p.push(OUTLINE);
    p.push(BACKGROUND);
    p.resize(256, [0, 0, 0]);
    p
}

/// Nearest-colour lookup from RGB to palette index, on 6 bits per channel.
pub struct Quantiser {
    table: Vec<u8>,
}

impl Quantiser {
    /// Builds the table for `palette` (its first 255 entries are candidates).
    pub fn new(palette: &[[u8; 3]]) -> Quantiser {
        let candidates = &palette[..palette.len().min(TRANSPARENT as usize)];
        let mut table = vec![0u8; 1 << 18];
        for (key, slot) in table.iter_mut().enumerate() {
            let c = [
                ((key >> 12) & 63) as i32 * 4 + 2,
                ((key >> 6) & 63) as i32 * 4 + 2,
                (key & 63) as i32 * 4 + 2,
            ];
            let mut best = (i32::MAX, 0usize);
            for (i, p) in candidates.iter().enumerate() {
                let d: i32 = (0..3).map(|k| (c[k] - p[k] as i32).pow(2)).sum();
                if d < best.0 {
                    best = (d, i);
                }
            }
            *slot = best.1 as u8;
        }
        Quantiser { table }
    }

    /// The palette index of an RGB colour. Exact palette colours map to themselves when no
    /// other entry shares their 6-bit cell; otherwise to the nearest entry of that cell's
    /// centre.
    pub fn index(&self, c: &[u8]) -> u8 {
        let key = ((c[0] as usize >> 2) << 12) | ((c[1] as usize >> 2) << 6) | (c[2] as usize >> 2);
        self.table[key]
    }
}

/// Centisecond delays of the frames at `times` (s) played at `speed`: frame j ends at the
/// centisecond nearest to (t_{j+1} − t_0)/speed, at least [`MIN_DELAY`] after it starts; the
/// last is held [`LAST_FRAME_HOLD`].
pub fn delays(times: &[f64], speed: f64) -> Vec<u16> {
    let mut out = Vec::with_capacity(times.len());
    let mut shown_until = 0i64; // centiseconds
    for j in 0..times.len() {
        if j + 1 == times.len() {
            out.push(LAST_FRAME_HOLD);
            break;
        }
        let end = ((times[j + 1] - times[0]) / speed * 100.0).round() as i64;
        let d = (end - shown_until).clamp(MIN_DELAY as i64, u16::MAX as i64);
        shown_until += d;
        out.push(d as u16);
    }
    out
}

/// The caption of a frame: its time and the largest |θ| of any coordinate so far; after the
/// run's first hypotheses violation (`outside_from`, s), that the motion shown is outside crr's
/// model.
pub fn caption(state: &State, outside_from: Option<f64>) -> String {
    if outside_from.is_some_and(|t| state.t > t) {
        return format!(
            "t = {:.2} s   max |θ| {:.4} rad   outside crr's model",
            state.t, state.peak_so_far
        );
    }
    format!(
        "t = {:.2} s    max |θ| so far = {:.4} rad ({:.2}°)",
        state.t,
        state.peak_so_far,
        state.peak_so_far.to_degrees()
    )
}

/// Writes the animated GIF frame by frame (so that a long animation never holds more than
/// one frame): [`GifWriter::new`] with the renderer (fitted to every frame beforehand) and the
/// frames' times, then [`GifWriter::add`] for each frame in order, then [`GifWriter::finish`].
pub struct GifWriter<W: std::io::Write> {
    encoder: ::gif::Encoder<W>,
    renderer: Renderer,
    quantiser: Quantiser,
    ground_faces: Vec<Face>,
    delays: Vec<u16>,
    rgb: Vec<u8>,
    previous: Option<Vec<u8>>,
    written: usize,
    /// The time after which the run is outside crr's model (its first hypotheses violation).
    outside_from: Option<f64>,
}

fn encode_error(e: ::gif::EncodingError) -> Error {
    Error::Argument(format!("cannot encode the GIF: {e}"))
}

/// The faces of the ground slab ([`ground_slab`]), in the ground's colour.
pub fn ground_faces(ground: &Ground) -> (Surface, Vec<Face>) {
    let slab = ground_slab(ground);
    let faces = slab
        .faces
        .iter()
        .map(|f| Face {
            points: f.iter().map(|&i| slab.vertices[i]).collect(),
            colour: GROUND_COLOUR,
        })
        .collect();
    (slab, faces)
}

impl<W: std::io::Write> GifWriter<W> {
    /// Starts the GIF on `out`: `renderer` fitted to every frame, `times` the frames' times
    /// (s), played at `speed`.
    pub fn new(
        out: W,
        renderer: Renderer,
        ground: &Ground,
        times: &[f64],
        speed: f64,
        outside_from: Option<f64>,
    ) -> Result<Self, Error> {
        let palette = palette();
        let flat: Vec<u8> = palette.iter().flatten().copied().collect();
        let mut encoder =
            ::gif::Encoder::new(out, WIDTH as u16, HEIGHT as u16, &flat).map_err(encode_error)?;
        encoder
            .set_repeat(::gif::Repeat::Infinite)
            .map_err(encode_error)?;
        Ok(GifWriter {
            encoder,
            renderer,
            quantiser: Quantiser::new(&palette),
            ground_faces: ground_faces(ground).1,
            delays: delays(times, speed),
            rgb: vec![0u8; 3 * (WIDTH * HEIGHT) as usize],
            previous: None,
            written: 0,
            outside_from,
        })
    }

    /// Draws and writes the next frame: `state` (for the caption) and the bodies' world
    /// vertices `pose` (one vector per body, as [`super::pose_vertices`] gives), with the
    /// bodies' `surfaces`.
    pub fn add(
        &mut self,
        state: &State,
        surfaces: &[Surface],
        pose: &[Vec<Vector3<f64>>],
    ) -> Result<(), Error> {
        let j = self.written;
        let delay = *self.delays.get(j).ok_or_else(|| {
            Error::Argument(format!("GIF frame {j} is beyond the frames announced"))
        })?;
        let mut faces = self.ground_faces.clone();
        for (b, (surface, verts)) in surfaces.iter().zip(pose).enumerate() {
            let colour = b % GROUND_COLOUR;
            faces.extend(surface.faces.iter().map(|f| Face {
                points: f.iter().map(|&i| verts[i]).collect(),
                colour,
            }));
        }
        self.renderer
            .draw(&faces, &caption(state, self.outside_from), &mut self.rgb);
        let indexed: Vec<u8> = self
            .rgb
            .chunks_exact(3)
            .map(|c| self.quantiser.index(c))
            .collect();
        let frame = match &self.previous {
            None => ::gif::Frame {
                width: WIDTH as u16,
                height: HEIGHT as u16,
                buffer: Cow::Borrowed(&indexed),
                delay,
                dispose: ::gif::DisposalMethod::Keep,
                ..::gif::Frame::default()
            },
            Some(prev) => changed_rect(prev, &indexed, delay),
        };
        self.encoder.write_frame(&frame).map_err(encode_error)?;
        self.previous = Some(indexed);
        self.written += 1;
        Ok(())
    }

    /// Ends the GIF (its trailer) and returns the writer.
    pub fn finish(self) -> Result<W, Error> {
        self.encoder
            .into_inner()
            .map_err(|e| Error::Argument(format!("cannot write the GIF: {e}")))
    }
}

/// The part of `next` that differs from `prev` as a frame drawn over it: the bounding
/// rectangle of the changed pixels, unchanged ones inside it [`TRANSPARENT`] (a 1 × 1
/// transparent frame when nothing changed).
fn changed_rect<'a>(prev: &[u8], next: &[u8], delay: u16) -> ::gif::Frame<'a> {
    let w = WIDTH as usize;
    let (mut x0, mut x1, mut y0, mut y1) = (usize::MAX, 0, usize::MAX, 0);
    for (i, (a, b)) in prev.iter().zip(next).enumerate() {
        if a != b {
            let (x, y) = (i % w, i / w);
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
    }
    if x0 == usize::MAX {
        (x0, x1, y0, y1) = (0, 0, 0, 0);
    }
    let mut buffer = Vec::with_capacity((x1 - x0 + 1) * (y1 - y0 + 1));
    for y in y0..=y1 {
        for x in x0..=x1 {
            let i = y * w + x;
            buffer.push(if prev[i] == next[i] {
                TRANSPARENT
            } else {
                next[i]
            });
        }
    }
    ::gif::Frame {
        left: x0 as u16,
        top: y0 as u16,
        width: (x1 - x0 + 1) as u16,
        height: (y1 - y0 + 1) as u16,
        buffer: Cow::Owned(buffer),
        delay,
        dispose: ::gif::DisposalMethod::Keep,
        transparent: Some(TRANSPARENT),
        ..::gif::Frame::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn delays_follow_real_time_without_drift() {
        // 0.05 s apart at speed 1: 5 cs each; the last held.
        let t: Vec<f64> = (0..5).map(|j| 0.05 * j as f64).collect();
        assert_eq!(delays(&t, 1.0), vec![5, 5, 5, 5, LAST_FRAME_HOLD]);
        // 0.033 s apart: 3.3 cs each, rounded so that frame j ends at round(3.3 (j+1)).
        let t: Vec<f64> = (0..7).map(|j| 0.033 * j as f64).collect();
        let d = delays(&t, 1.0);
        let total: u32 = d[..6].iter().map(|&x| x as u32).sum();
        assert_eq!(total, (0.033f64 * 6.0 * 100.0).round() as u32);
        // Half speed doubles them; too short delays are raised to MIN_DELAY.
        assert_eq!(delays(&[0.0, 0.05, 0.1], 0.5)[..2], [10, 10]);
        assert_eq!(
            delays(&[0.0, 0.001, 0.002], 1.0)[..2],
            [MIN_DELAY, MIN_DELAY]
        );
    }

    #[test]
    fn palette_colours_map_to_themselves() {
        let p = palette();
        assert_eq!(p.len(), 256);
        let q = Quantiser::new(&p);
        // Every shade and the background are drawn exactly (their 6-bit cells hold no closer
        // entry), so quantising loses nothing on the faces.
        for (i, c) in p.iter().enumerate().take(BASE_COLOURS.len() * SHADE_LEVELS) {
            let back = p[q.index(c) as usize];
            let d: i32 = (0..3)
                .map(|k| (back[k] as i32 - c[k] as i32).abs())
                .max()
                .unwrap();
            assert!(d <= 4, "entry {i} {c:?} maps to {back:?}");
        }
        assert_eq!(p[q.index(&BACKGROUND) as usize], BACKGROUND);
    }
}
