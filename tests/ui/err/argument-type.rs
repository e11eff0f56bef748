use radiosity::oracle;

oracle! {
    crate = ::radiosity;
    oracle Rays {
        params { eps: f64 = 0.5 in 0.0..=1.0 }
        start => v;
        v: RayVisibility(eps) {
            Visible | ProbablyVisible => link,
            Invisible | ProbablyInvisible => stop,
            Partial | ProbablyPartial | TooComplex => subdivide_both,
        }
    }
}

fn main() {}
