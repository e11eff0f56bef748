use radiosity::oracle;

oracle! {
    crate = ::radiosity;
    oracle Partial {
        start => size;
        size: CanSubdivide(0.0) { Neither => link, Both => subdivide_both }
    }
}

fn main() {}
