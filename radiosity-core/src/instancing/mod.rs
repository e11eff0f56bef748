//! Hierarchical instantiation: prototypes, instances, cached radiative properties, depth-first solve.
