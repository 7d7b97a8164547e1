//! A small software rasteriser for the GIF frames: orthographic projection along a view
//! direction, back faces dropped, the other faces sorted far to near and filled (painter's
//! algorithm) with a flat shade of their body's colour by the angle of their normal to the
//! light, and outlined; the text (time, peak rotation) drawn by plotters with the embedded
//! DejaVu Sans.

use nalgebra::Vector3;
use plotters::prelude::*;

use crr_kinematics::shapes::{BoxShape, Surface};

use super::Ground;
use crate::output::plot::{FONT, register_fonts};

/// Image width of the GIF (pixels).
pub const WIDTH: u32 = 480;

/// Image height of the GIF (pixels).
pub const HEIGHT: u32 = 360;

/// Height of the text band at the top of every frame (pixels).
pub const TEXT_BAND: u32 = 26;

/// Margin around the drawing (pixels).
const MARGIN: f64 = 10.0;

/// Shades of every base colour: a face's shade is `SHADE_FLOOR + (1 − SHADE_FLOOR) · s`, s the
/// cosine of its normal with the light (clamped at 0) rounded to one of these levels.
pub const SHADE_LEVELS: usize = 24;

/// The darkest shade (a face turned away from the light), as a fraction of the base colour.
pub const SHADE_FLOOR: f64 = 0.35;

/// The bodies' base colours (cycled when there are more bodies), then the ground's.
pub const BASE_COLOURS: [[u8; 3]; 9] = [
    [214, 160, 96],  // sandstone
    [92, 140, 200],  // blue
    [200, 96, 88],   // brick red
    [112, 176, 112], // green
    [176, 128, 200], // violet
    [224, 200, 96],  // ochre
    [96, 184, 184],  // teal
    [200, 140, 168], // rose
    [150, 150, 150], // ground grey
];

/// Index of the ground's base colour in [`BASE_COLOURS`].
pub const GROUND_COLOUR: usize = 8;

/// The outline colour.
pub const OUTLINE: [u8; 3] = [40, 40, 40];

/// The background colour.
pub const BACKGROUND: [u8; 3] = [255, 255, 255];

/// The direction the GIF is seen from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum View {
    /// Along the x axis (from +x): y to the right, z up.
    X,
    /// Along the y axis (from −y): x to the right, z up.
    Y,
    /// From above (from +z): x to the right, y up.
    Z,
    /// Isometric, from (1, −1, 1): z up.
    Iso,
}

impl std::str::FromStr for View {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "x" => Ok(View::X),
            "y" => Ok(View::Y),
            "z" => Ok(View::Z),
            "iso" => Ok(View::Iso),
            _ => Err(format!("unknown view `{s}`: give x, y, z or iso")),
        }
    }
}

/// An orthographic camera: screen axes `right`, `up` and `toward` (pointing to the viewer),
/// a right-handed orthonormal frame.
#[derive(Clone, Copy, Debug)]
pub struct Camera {
    /// Screen x direction (world).
    pub right: Vector3<f64>,
    /// Screen y direction (world).
    pub up: Vector3<f64>,
    /// From the scene to the viewer (world); `right × up = toward`.
    pub toward: Vector3<f64>,
}

impl View {
    /// The camera of this view.
    pub fn camera(self) -> Camera {
        let (right, up) = match self {
            View::X => (Vector3::y(), Vector3::z()),
            View::Y => (Vector3::x(), Vector3::z()),
            View::Z => (Vector3::x(), Vector3::y()),
            View::Iso => {
                let toward = Vector3::new(1.0, -1.0, 1.0).normalize();
                let right = Vector3::z().cross(&toward).normalize();
                (right, toward.cross(&right))
            }
        };
        Camera {
            right,
            up,
            toward: right.cross(&up),
        }
    }

    /// The option's name.
    pub fn name(self) -> &'static str {
        match self {
            View::X => "x",
            View::Y => "y",
            View::Z => "z",
            View::Iso => "iso",
        }
    }
}

/// A face to draw: its world vertices and base colour (index into [`BASE_COLOURS`]).
#[derive(Clone, Debug)]
pub struct Face {
    /// World vertices, counter-clockwise seen from outside.
    pub points: Vec<Vector3<f64>>,
    /// Base colour.
    pub colour: usize,
}

/// The colour of shade `level` (0 ..= [`SHADE_LEVELS`] − 1) of base colour `base`.
pub fn shade(base: usize, level: usize) -> [u8; 3] {
    let f = SHADE_FLOOR + (1.0 - SHADE_FLOOR) * level as f64 / (SHADE_LEVELS - 1) as f64;
    BASE_COLOURS[base].map(|c| (c as f64 * f).round() as u8)
}

/// The ground slab drawn in the GIF: the ground rectangle, 4 % of its longer side thick.
pub fn ground_slab(ground: &Ground) -> Surface {
    let [a, _, c, _] = ground.corners;
    let size = c - a;
    let h = 0.04 * size.x.max(size.y);
    let shape = BoxShape {
        center: [(a.x + c.x) / 2.0, (a.y + c.y) / 2.0, a.z - h / 2.0],
        size: [size.x, size.y, h],
        rotation: None,
    };
    shape.surface().expect("a box of positive sides")
}

/// Projection of the world onto the image: fixed for a whole animation so that the picture
/// does not move between frames.
#[derive(Clone, Debug)]
pub struct Renderer {
    camera: Camera,
    light: Vector3<f64>,
    scale: f64,
    centre: (f64, f64),
    origin: (f64, f64),
}

impl Renderer {
    /// A renderer for `view` that fits every point of `points` (all frames' vertices and the
    /// ground) in the image below the text band, with equal scales on both screen axes.
    pub fn new(view: View, points: impl IntoIterator<Item = Vector3<f64>>) -> Renderer {
        let camera = view.camera();
        let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for p in points {
            let (x, y) = (camera.right.dot(&p), camera.up.dot(&p));
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
        if x0 > x1 {
            (x0, x1, y0, y1) = (-1.0, 1.0, -1.0, 1.0);
        }
        let avail_w = WIDTH as f64 - 2.0 * MARGIN;
        let avail_h = (HEIGHT - TEXT_BAND) as f64 - 2.0 * MARGIN;
        let span_x = (x1 - x0).max(1e-9);
        let span_y = (y1 - y0).max(1e-9);
        let scale = (avail_w / span_x).min(avail_h / span_y);
        let light = (camera.toward * 0.8 + camera.up * 0.5 + camera.right * 0.3).normalize();
        Renderer {
            camera,
            light,
            scale,
            centre: ((x0 + x1) / 2.0, (y0 + y1) / 2.0),
            origin: (
                WIDTH as f64 / 2.0,
                TEXT_BAND as f64 + (HEIGHT - TEXT_BAND) as f64 / 2.0,
            ),
        }
    }

    /// Pixel coordinates (x right, y down; pixel (i, j) covers [i, i+1) × [j, j+1)) of a
    /// world point.
    pub fn project(&self, p: &Vector3<f64>) -> (f64, f64) {
        let x = self.camera.right.dot(p) - self.centre.0;
        let y = self.camera.up.dot(p) - self.centre.1;
        (
            self.origin.0 + self.scale * x,
            self.origin.1 - self.scale * y,
        )
    }

    /// Draws one frame into `rgb` (WIDTH × HEIGHT × 3 bytes, row-major): background, the faces
    /// far to near, then the `caption` lines in the text band.
    pub fn draw(&self, faces: &[Face], caption: &str, rgb: &mut [u8]) {
        for px in rgb.chunks_exact_mut(3) {
            px.copy_from_slice(&BACKGROUND);
        }
        let mut visible: Vec<(f64, &Face, usize)> = faces
            .iter()
            .filter_map(|f| {
                let m = f.points.len();
                let normal = (0..m).fold(Vector3::zeros(), |acc, i| {
                    acc + f.points[i].cross(&f.points[(i + 1) % m])
                });
                let norm = normal.norm();
                if norm == 0.0 {
                    return None;
                }
                let n = normal / norm;
                // Back faces (and faces seen edge-on) are hidden by the closed bodies.
                if n.dot(&self.camera.toward) <= 1e-9 {
                    return None;
                }
                let depth = f
                    .points
                    .iter()
                    .map(|p| self.camera.toward.dot(p))
                    .sum::<f64>()
                    / m as f64;
                let s = n.dot(&self.light).max(0.0);
                let level = (s * (SHADE_LEVELS - 1) as f64).round() as usize;
                Some((depth, f, level.min(SHADE_LEVELS - 1)))
            })
            .collect();
        visible.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut canvas = Canvas {
            rgb,
            depth: vec![f64::NEG_INFINITY; (WIDTH * HEIGHT) as usize],
            // Depths within a thousandth of a pixel's size are ties (the later face wins).
            tolerance: 1e-3 / self.scale,
            // An outline is drawn unless a surface lies two pixels' size in front of it: the
            // depths stored at pixel centres differ from the edge's by up to a pixel's worth
            // of the face's slope.
            line_tolerance: 2.0 / self.scale,
        };
        for (_, face, level) in visible {
            let pts: Vec<(f64, f64)> = face.points.iter().map(|p| self.project(p)).collect();
            let depths: Vec<f64> = face
                .points
                .iter()
                .map(|p| self.camera.toward.dot(p))
                .collect();
            // The face's plane: depth at a pixel from its screen position.
            let n = face_normal(&face.points);
            let (nr, nu, nt) = (
                n.dot(&self.camera.right),
                n.dot(&self.camera.up),
                n.dot(&self.camera.toward),
            );
            let plane = n.dot(&face.points[0]);
            let depth_at = |px: f64, py: f64| {
                let x = (px - self.origin.0) / self.scale + self.centre.0;
                let y = -(py - self.origin.1) / self.scale + self.centre.1;
                (plane - nr * x - nu * y) / nt
            };
            canvas.fill_polygon(&pts, &depth_at, shade(face.colour, level));
            for i in 0..pts.len() {
                let j = (i + 1) % pts.len();
                canvas.line((pts[i], depths[i]), (pts[j], depths[j]), OUTLINE);
            }
        }
        draw_text(rgb, caption);
    }
}

/// Unit normal of a planar polygon (Newell).
fn face_normal(points: &[Vector3<f64>]) -> Vector3<f64> {
    let m = points.len();
    (0..m)
        .fold(Vector3::zeros(), |acc, i| {
            acc + points[i].cross(&points[(i + 1) % m])
        })
        .normalize()
}

/// The image being drawn and its depth buffer (the distance towards the viewer of the
/// nearest surface drawn at each pixel): the faces come far to near (painter's order), and a
/// pixel is only painted over by a surface at least as near, so that faces whose order the
/// sort gets wrong (a long face beside a short one) still hide each other correctly.
pub struct Canvas<'a> {
    /// WIDTH × HEIGHT × 3 bytes, row-major.
    pub rgb: &'a mut [u8],
    /// WIDTH × HEIGHT depths (m, towards the viewer).
    pub depth: Vec<f64>,
    /// Depth differences below this are ties (m).
    pub tolerance: f64,
    /// How far (m) an outline may lie behind the nearest surface drawn and still be drawn.
    pub line_tolerance: f64,
}

impl Canvas<'_> {
    /// Paints pixel (x, y) with `c` if a surface at depth `d` is not behind what is there by
    /// more than `slack`; a fill (`record`) also records its depth, an outline does not.
    fn put(&mut self, x: i64, y: i64, d: f64, slack: f64, record: bool, c: [u8; 3]) {
        if x >= 0 && y >= 0 && (x as u32) < WIDTH && (y as u32) < HEIGHT {
            let k = y as usize * WIDTH as usize + x as usize;
            if d + slack >= self.depth[k] {
                if record {
                    self.depth[k] = self.depth[k].max(d);
                }
                self.rgb[3 * k..3 * k + 3].copy_from_slice(&c);
            }
        }
    }

    /// Fills a polygon (any simple polygon, even-odd rule) by scanlines through the pixel
    /// centres; `depth(x, y)` gives its depth at a pixel centre.
    pub fn fill_polygon(
        &mut self,
        pts: &[(f64, f64)],
        depth: &dyn Fn(f64, f64) -> f64,
        c: [u8; 3],
    ) {
        let (mut y0, mut y1) = (f64::MAX, f64::MIN);
        for p in pts {
            y0 = y0.min(p.1);
            y1 = y1.max(p.1);
        }
        let first = (y0 - 0.5).ceil().max(0.0) as i64;
        let last = ((y1 - 0.5).floor()).min(HEIGHT as f64 - 1.0) as i64;
        let mut xs: Vec<f64> = Vec::with_capacity(8);
        for row in first..=last {
            let yc = row as f64 + 0.5;
            xs.clear();
            for i in 0..pts.len() {
                let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
                // Half-open in y so that a vertex on the scanline counts once.
                if (a.1 <= yc) != (b.1 <= yc) {
                    xs.push(a.0 + (yc - a.1) / (b.1 - a.1) * (b.0 - a.0));
                }
            }
            xs.sort_by(f64::total_cmp);
            for pair in xs.chunks_exact(2) {
                let from = (pair[0] - 0.5).ceil().max(0.0) as i64;
                let to = ((pair[1] - 0.5).floor()).min(WIDTH as f64 - 1.0) as i64;
                for x in from..=to {
                    let d = depth(x as f64 + 0.5, yc);
                    self.put(x, row, d, self.tolerance, true, c);
                }
            }
        }
    }

    /// A one-pixel line between two points with their depths (DDA, depth interpolated).
    pub fn line(&mut self, a: ((f64, f64), f64), b: ((f64, f64), f64), c: [u8; 3]) {
        let ((a, da), (b, db)) = (a, b);
        let steps = (b.0 - a.0).abs().max((b.1 - a.1).abs()).ceil().max(1.0);
        if !steps.is_finite() || steps > 1e5 {
            return;
        }
        let n = steps as i64;
        for i in 0..=n {
            let f = i as f64 / steps;
            let x = a.0 + f * (b.0 - a.0);
            let y = a.1 + f * (b.1 - a.1);
            let d = da + f * (db - da);
            let slack = self.line_tolerance;
            self.put(x.floor() as i64, y.floor() as i64, d, slack, false, c);
        }
    }
}

/// Draws the caption in the text band (DejaVu Sans 14 px, black).
fn draw_text(rgb: &mut [u8], caption: &str) {
    register_fonts();
    let root = BitMapBackend::with_buffer(rgb, (WIDTH, HEIGHT)).into_drawing_area();
    let style = (FONT, 14).into_font().color(&BLACK);
    // A failure to draw the text leaves the frame without it; the geometry is still right.
    let _ = root.draw_text(caption, &style, (8, 6));
    let _ = root.present();
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cameras_are_right_handed_and_look_along_their_axis() {
        for (view, toward) in [
            (View::X, Vector3::x()),
            (View::Y, -Vector3::y()),
            (View::Z, Vector3::z()),
            (View::Iso, Vector3::new(1.0, -1.0, 1.0).normalize()),
        ] {
            let c = view.camera();
            assert!((c.toward - toward).norm() < 1e-15, "{view:?}");
            assert!((c.right.cross(&c.up) - c.toward).norm() < 1e-15);
            assert!(c.right.dot(&c.up).abs() < 1e-15);
            // z is never drawn downwards.
            assert!(c.up.z >= 0.0);
        }
    }

    fn canvas(rgb: &mut [u8]) -> Canvas<'_> {
        Canvas {
            rgb,
            depth: vec![f64::NEG_INFINITY; (WIDTH * HEIGHT) as usize],
            tolerance: 1e-9,
            line_tolerance: 1e-9,
        }
    }

    fn count(rgb: &[u8], c: [u8; 3]) -> usize {
        rgb.chunks_exact(3).filter(|p| *p == c).count()
    }

    #[test]
    fn a_filled_square_covers_the_pixel_centres_inside_it() {
        let mut rgb = vec![0u8; (3 * WIDTH * HEIGHT) as usize];
        // Corners at pixel boundaries 10..20 × 30..40: exactly 10 × 10 pixel centres inside.
        let square = [(10.0, 30.0), (20.0, 30.0), (20.0, 40.0), (10.0, 40.0)];
        canvas(&mut rgb).fill_polygon(&square, &|_, _| 0.0, [1, 2, 3]);
        assert_eq!(count(&rgb, [1, 2, 3]), 100);
        // A triangle of half the square: 45 centres strictly below the diagonal plus the 10
        // on it counted on one side (55 = 10·11/2).
        let mut rgb = vec![0u8; (3 * WIDTH * HEIGHT) as usize];
        let triangle = [(10.0, 30.0), (20.0, 40.0), (10.0, 40.0)];
        canvas(&mut rgb).fill_polygon(&triangle, &|_, _| 0.0, [1, 2, 3]);
        assert_eq!(count(&rgb, [1, 2, 3]), 55);
    }

    #[test]
    fn a_farther_face_drawn_later_stays_hidden() {
        let mut rgb = vec![0u8; (3 * WIDTH * HEIGHT) as usize];
        let mut c = canvas(&mut rgb);
        let square = [(10.0, 30.0), (20.0, 30.0), (20.0, 40.0), (10.0, 40.0)];
        c.fill_polygon(&square, &|_, _| 1.0, [1, 2, 3]);
        // The right half again, farther away (depth 0 < 1): not drawn.
        let half = [(15.0, 30.0), (20.0, 30.0), (20.0, 40.0), (15.0, 40.0)];
        c.fill_polygon(&half, &|_, _| 0.0, [9, 9, 9]);
        // A nearer one is.
        let quarter = [(10.0, 30.0), (15.0, 30.0), (15.0, 35.0), (10.0, 35.0)];
        c.fill_polygon(&quarter, &|_, _| 2.0, [7, 7, 7]);
        assert_eq!(count(&rgb, [9, 9, 9]), 0);
        assert_eq!(count(&rgb, [7, 7, 7]), 25);
        assert_eq!(count(&rgb, [1, 2, 3]), 75);
    }

    #[test]
    fn the_fitted_projection_keeps_every_point_in_the_drawing_area() {
        let pts = [
            Vector3::new(-1.0, 0.0, 0.0),
            Vector3::new(1.0, 0.5, 3.0),
            Vector3::new(0.2, -0.3, 1.0),
        ];
        for view in [View::X, View::Y, View::Z, View::Iso] {
            let r = Renderer::new(view, pts);
            for p in &pts {
                let (x, y) = r.project(p);
                // Inside the margins, to round-off (1e-9 px).
                assert!(x >= MARGIN - 1e-9 && x <= WIDTH as f64 - MARGIN + 1e-9);
                assert!(y >= TEXT_BAND as f64 + MARGIN - 1e-9);
                assert!(y <= HEIGHT as f64 - MARGIN + 1e-9);
            }
        }
    }
}
