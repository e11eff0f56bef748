use radiosity::oracle;

oracle! {
    crate = ::radiosity;
    oracle Mystery {
        start => a;
        a: Facingg { Yes => link, No => stop }
    }
}

fn main() {}
