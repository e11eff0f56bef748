use radiosity::oracle;

oracle! {
    crate = ::radiosity;
    oracle Looping {
        start => a;
        a: Facing { Yes => b, No => stop }
        b: ClusterTooNear { Yes => a, No => link }
    }
}

fn main() {}
