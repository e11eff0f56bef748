use radiosity_core::pipeline;
use radiosity_core::refine::{BfHand, BfParams, Criterion};
use std::collections::HashMap;
fn main() {
    let path = std::path::Path::new(&std::env::args().nth(1).unwrap()).to_owned();
    let (scene, lighting) = radiosity_core::instancing::load_with_lighting(&path).unwrap();
    let mut plain = radiosity_core::instancing::flatten(&scene, &Default::default()).unwrap();
    plain.luminaires = lighting.luminaires;
    plain.units = lighting.units;
    plain.distant = lighting.bands.pack_distant(0);
    let crit = if std::env::args().nth(2).as_deref() == Some("irr") { Criterion::Irradiance } else { Criterion::Radiosity };
    let config = pipeline::Config { target_error: Some(0.01), criterion: crit, ..pipeline::Config::default() };
    let t = std::time::Instant::now();
    let s = pipeline::run(&plain, &BfHand { params: BfParams::default() }, &config, &|_| {});
    let h = &s.hierarchy;
    println!("{} links {} leaves {:.1}s", s.links.len(), h.leaves().count(), t.elapsed().as_secs_f64());
    for l in &s.levels {
        println!("  level {:?}", (l.threshold_scale, l.links, l.error_estimate));
    }
    let poly = |e: u32| h.get(e).polygon().map_or(-1i64, |p| p as i64);
    let mut by_r: HashMap<i64, usize> = HashMap::new();
    let mut by_s: HashMap<i64, usize> = HashMap::new();
    let mut part = 0;
    let mut depth: HashMap<u16, usize> = HashMap::new();
    for l in &s.links {
        *by_r.entry(poly(l.receiver)).or_default() += 1;
        *by_s.entry(poly(l.source)).or_default() += 1;
        if l.vis > 0.0 && l.vis < 1.0 {
            part += 1;
        }
        *depth.entry(h.get(l.receiver).depth).or_default() += 1;
    }
    let mut v: Vec<_> = by_r.into_iter().collect();
    v.sort_by_key(|x| std::cmp::Reverse(x.1));
    println!("partial {part}; by receiver polygon (area, rho, H): ");
    for (p, n) in v.iter().take(12) {
        if *p >= 0 {
            let e = h.get(*p as u32);
            println!(
                "  {p} {n} area {:.3} rho {:?} H {:.3} leaves {}",
                e.area,
                h.reflectance[*p as usize][1],
                s.solution.irradiance[*p as usize][1],
                h.leaves().filter(|&x| h.get(x).polygon() == Some(*p as u32)).count()
            );
        } else {
            println!("  cluster {n}");
        }
    }
    let mut v: Vec<_> = by_s.into_iter().collect();
    v.sort_by_key(|x| std::cmp::Reverse(x.1));
    println!("by source polygon: {:?}", &v[..v.len().min(12)]);
    let mut d: Vec<_> = depth.into_iter().collect();
    d.sort();
    println!("receiver depth: {d:?}");
}
