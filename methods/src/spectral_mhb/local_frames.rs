//! Adding details back in local frames (Rong et al. 2008, section 4.4, the faster alternative to
//! deformation transfer): the detail vector `p_i - p~_i` between the original and the smoothed model is
//! stored in a frame at each smoothed vertex and re-applied in the frame of the deformed smoothed model.
//! Frame: `z` = vertex normal; `e` = the first edge of the first triangle incident to the vertex,
//! normalized; `x = e x z`, `y = z x x` (the paper's construction; `x` is normalized since `e` need
//! not be orthogonal to `z`).

use meshes::vector::{cross, dot, normalize_or_zero, scale, sub};

/// Detail vectors in local frames of the smoothed rest model.
pub struct LocalFrameDetails {
    triangles: Vec<[u32; 3]>,
    /// Per vertex: the vertex at the other end of its frame edge.
    frame_neighbor: Vec<u32>,
    /// Per vertex: detail vector in `(x, y, z)` coordinates.
    coefficients: Vec<[f64; 3]>,
}

impl LocalFrameDetails {
    /// Encode `rest - smoothed` (`#V x 3` each) in frames of `smoothed`.
    pub fn new(rest: &[[f64; 3]], smoothed: &[[f64; 3]], triangles: &[[u32; 3]]) -> Self {
        let n = rest.len();
        let mut frame_neighbor: Vec<u32> = (0..n as u32).collect();
        let mut assigned = vec![false; n];
        for t in triangles {
            for k in 0..3 {
                let v = t[k] as usize;
                if !assigned[v] {
                    assigned[v] = true;
                    frame_neighbor[v] = t[(k + 1) % 3];
                }
            }
        }
        let normals = meshes::geometry::vertex_normals(smoothed, triangles);
        let coefficients = (0..n)
            .map(|i| {
                let (x, y, z) = local_frame(smoothed, &normals, frame_neighbor[i], i);
                let d = sub(rest[i], smoothed[i]);
                [dot(d, x), dot(d, y), dot(d, z)]
            })
            .collect();
        Self { triangles: triangles.to_vec(), frame_neighbor, coefficients }
    }

    /// Detailed positions (`#V x 3`) on the deformed smoothed model `smoothed_deformed` (`#V x 3`).
    pub fn transfer(&self, smoothed_deformed: &[[f64; 3]]) -> Vec<[f64; 3]> {
        let normals = meshes::geometry::vertex_normals(smoothed_deformed, &self.triangles);
        (0..smoothed_deformed.len())
            .map(|i| {
                let (x, y, z) = local_frame(smoothed_deformed, &normals, self.frame_neighbor[i], i);
                let c = self.coefficients[i];
                let d: [f64; 3] = std::array::from_fn(|a| c[0] * x[a] + c[1] * y[a] + c[2] * z[a]);
                meshes::vector::add(smoothed_deformed[i], d)
            })
            .collect()
    }
}

fn local_frame(
    p: &[[f64; 3]],
    normals: &[[f64; 3]],
    neighbor: u32,
    i: usize,
) -> ([f64; 3], [f64; 3], [f64; 3]) {
    let z = normals[i];
    let e = normalize_or_zero(sub(p[neighbor as usize], p[i]));
    let x = normalize_or_zero(cross(e, z));
    let y = cross(z, x);
    (x, y, scale(z, 1.0))
}
