use radiosity::oracle;

oracle! {
    crate = ::radiosity;
    oracle Hollow {
        start => a;
        a: Facing {}
    }
}

fn main() {}
