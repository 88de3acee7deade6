//! Post-processing shared by every code: cgdem's own state and the reference codes' dumps
//! go through the same functions (heap profiles and repose angles; porosity, distance
//! transforms and pore-size distributions of packings).

pub mod conical_heap;
pub mod conveying;
pub mod distance_transform;
pub mod heap;
pub mod packing;
pub mod pore_size;
pub mod porosity;

pub use distance_transform::squared_distance_transform;
pub use packing::{measure_packing, PackingMeasurement, PackingSummary};
pub use pore_size::{
    pore_size_field, pore_size_field_of_spheres, rasterize_spheres, Boundary, PoreSizeDistribution,
    PoreSizeError, PoreSizeField, VoxelGrid,
};
pub use porosity::{
    bed_measurement_region, porosity_voxel, porosity_z_slab, sphere_slab_volume, MeasurementRegion,
    Porosity, PorosityError,
};
