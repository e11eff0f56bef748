use radiosity::oracle;

oracle! {
    crate = ::radiosity;
    oracle Lost {
        start => a;
        a: Facing { Yes => energy, No => stop }
    }
}

fn main() {}
