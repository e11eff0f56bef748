use radiosity::oracle;

oracle! {
    crate = ::radiosity;
    oracle Unset {
        start => a;
        a: BfAbove(epsilon) { Yes => subdivide_both, No => link }
    }
}

fn main() {}
