// A syntax error in an oracle that the code below uses: the syntax error is the only error, since
// the fallback of the oracle found in the input still gives that code its type and params.
use radiosity::oracle;

oracle! {
    crate = ::radiosity;
    pub oracle MyBf {
        params { eps: f64 = 0.01 in 0.0..=1.0 }
        start => energy;
        energy: BfAbove(eps) { No => link Yes => subdivide_both }
    }
}

fn main() {
    let bf = MyBf::new(MyBfParams { eps: 0.05 });
    let _ = bf.params.eps;
}
