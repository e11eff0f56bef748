// One mistake (an unhandled answer) in an oracle that the code below uses: the mistake is the only
// error, since the fallback still gives that code the oracle's type, params and constructors.
use radiosity::oracle;
use radiosity::oracle::NoProbe;
use radiosity::refine::Oracle;

oracle! {
    crate = ::radiosity;
    pub oracle MyBf {
        params { eps: f64 = 0.01 in 0.0..=1.0, min_area: f64 = 0.0 }
        start => energy;
        energy: BfAbove(eps) { No => link, Yes => size }
        size: CanSubdivide(min_area) { Neither => link, Both => subdivide_both }
    }
}

fn main() {
    let mut params = MyBfParams { eps: 0.05, ..MyBfParams::default() };
    params.set("min_area", 1e-4).unwrap();
    let bf = MyBf::new(params);
    let probed = MyBf::with_probe(params, NoProbe);
    let _ = (bf.name(), probed.params.eps, params.get("eps"), MyBf::<NoProbe>::GRAPH.nodes.len());
    let _: &dyn Oracle = &bf;
}
