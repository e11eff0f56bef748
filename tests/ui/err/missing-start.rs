use radiosity::oracle;

oracle! {
    crate = ::radiosity;
    oracle Nowhere {
        a: Facing { Yes => link, No => stop }
    }
}

fn main() {}
