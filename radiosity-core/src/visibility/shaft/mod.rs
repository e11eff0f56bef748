//! Shaft visibility culling (Haines & Wallace): shafts between element boxes, candidate occluders,
//! conservative occlusion tests.
