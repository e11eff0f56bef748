use radiosity::oracle;

oracle! {
    crate = ::radiosity;
    oracle Island {
        start => a;
        a: Facing { Yes => link, No => stop }
        b: Larger { Emitter => link, Receiver => link }
    }
}

fn main() {}
