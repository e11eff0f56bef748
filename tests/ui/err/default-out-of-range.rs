use radiosity::oracle;

oracle! {
    crate = ::radiosity;
    oracle Wide {
        params { eps: f64 = 2.0 in 0.0..=1.0 }
        start => a;
        a: BfAbove(eps) { Yes => subdivide_both, No => link }
    }
}

fn main() {}
