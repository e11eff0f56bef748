use radiosity::oracle;

oracle! {
    crate = ::radiosity;
    oracle Again {
        start => a;
        a: Facing { Yes => link, No | Yes => stop }
    }
}

fn main() {}
