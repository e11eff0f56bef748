use radiosity::oracle;

oracle! {
    crate = ::radiosity;
    oracle Twice {
        start => a;
        a: Facing { Yes => link, No => stop }
        a: Larger { Emitter => link, Receiver => link }
    }
}

fn main() {}
