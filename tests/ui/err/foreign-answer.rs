use radiosity::oracle;

oracle! {
    crate = ::radiosity;
    oracle Foreign {
        start => a;
        a: Facing { Yes => link, No => stop, Emitter => link }
    }
}

fn main() {}
