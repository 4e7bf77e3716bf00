// Temporary diagnosis (not committed): where does a method's step stay large?
use std::ops::ControlFlow;
use harness::scenario::{load_spec, DataSource};
use methods::{IterationObserver, IterationReport};

struct Obs { last: Option<Vec<[f64;3]>>, prev: Option<Vec<[f64;3]>>, at: usize }
impl IterationObserver for Obs {
    fn on_iteration(&mut self, r: &IterationReport, shape: &dyn Fn() -> Vec<[f64; 3]>) -> ControlFlow<()> {
        if r.iteration + 2 >= self.at { self.prev = self.last.take(); self.last = Some(shape()); }
        if r.iteration % 100 == 0 { eprintln!("it {} step {:.3e}", r.iteration, r.step); }
        ControlFlow::Continue(())
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let spec = load_spec(std::path::Path::new(&args[1])).unwrap();
    let method = &args[2];
    let iters: usize = args[3].parse().unwrap();
    let sc = spec.load(&DataSource::Procedural).unwrap().remove(0);
    let text = std::fs::read_to_string("configs/methods.toml").unwrap();
    let cfg: toml::Table = text.parse().unwrap();
    let mut params = cfg[method.as_str()].as_table().unwrap().clone();
    params.insert("max_iterations".into(), (iters as i64).into());
    if args.len() > 4 { params.insert("acceleration".into(), args[4].clone().into()); }
    let mut m = methods::registry::create(method, &params).unwrap();
    m.precompute(&sc.mesh).unwrap();
    let step = &sc.steps[0];
    let targets = step.targets(&m.positions()).unwrap();
    m.bind_handles(&step.handles).unwrap();
    let mut obs = Obs { last: None, prev: None, at: iters };
    let s = m.solve(&targets, &mut obs).unwrap();
    eprintln!("{s:?}");
    let (a, b) = (obs.prev.unwrap(), obs.last.unwrap());
    let diag = sc.mesh.bbox_diagonal();
    let mut d: Vec<(f64, usize)> = a.iter().zip(&b).enumerate().map(|(i, (p, q))| (meshes::vector::norm(meshes::vector::sub(*p, *q)) / diag, i)).collect();
    d.sort_by(|x, y| y.0.total_cmp(&x.0));
    let (lo, hi) = sc.mesh.bbox();
    let tris = sc.mesh.triangles();
    let p = sc.mesh.positions();
    for &(dv, i) in d.iter().take(15) {
        let ring = sc.topology.one_ring(i);
        let mut min_angle = 180.0f64; let mut min_edge = f64::MAX;
        for t in tris.iter().filter(|t| t.contains(&(i as u32))) {
            for k in 0..3 { let (a0, a1, a2) = (p[t[k] as usize], p[t[(k+1)%3] as usize], p[t[(k+2)%3] as usize]);
                let u = meshes::vector::sub(a1, a0); let v = meshes::vector::sub(a2, a0);
                let c = meshes::vector::dot(u, v) / (meshes::vector::norm(u) * meshes::vector::norm(v));
                min_angle = min_angle.min(c.clamp(-1.0, 1.0).acos().to_degrees());
                min_edge = min_edge.min(meshes::vector::norm(u) / diag);
            }
        }
        let bc: Vec<String> = (0..3).map(|k| format!("{:.2}", (p[i][k] - lo[k]) / (hi[k] - lo[k]))).collect();
        eprintln!("v {i} step {dv:.2e} valence {} bbox ({}) min angle {min_angle:.2} min edge {min_edge:.1e} moved {:.3}", ring.len(), bc.join(","), meshes::vector::norm(meshes::vector::sub(b[i], p[i]))/diag);
    }
    let n_big = d.iter().filter(|x| x.0 > 1e-5).count();
    eprintln!("{} vertices stepped more than 1e-5", n_big);
}
