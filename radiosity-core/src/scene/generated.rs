//! Procedurally generated test scenes (interiors with stairs and beams, visibility test scenes).
