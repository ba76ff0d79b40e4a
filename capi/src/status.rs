//! Status codes and symmetry types: what every call returns, as C enums.

#[cfg(doc)]
use crate::{sfs_config_types, sfs_poll};
use shape_from_symmetry::{Error, SymmetryType};

/// What every `sfs_*` call returns: `SFS_STATUS_OK` (0), the two progress codes of
/// [`sfs_poll`] (positive), or an error (negative): one per library error, then the API's own.
/// (The function docs name them without the `SFS_STATUS_` prefix.)
#[repr(i32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SfsStatus {
    /// The call succeeded.
    Ok = 0,
    /// `sfs_poll`: more work remains; poll again (the results hold the best so far).
    Working = 1,
    /// `sfs_poll`: the search and the completion are finished; the results are final.
    Done = 2,
    /// The image width or height is zero.
    ErrEmptyImage = -1,
    /// A focal length is not positive and finite, or the principal point is not finite.
    ErrInvalidIntrinsics = -2,
    /// `depth_len` is not `width * height`.
    ErrDepthSizeMismatch = -3,
    /// `mask_len` is not `width * height` (with a non-null mask).
    ErrMaskSizeMismatch = -4,
    /// The depth scale is not in (0, 1] metres per unit.
    ErrInvalidDepthScale = -5,
    /// The table normal is not a finite unit vector, or its offset is not finite.
    ErrInvalidTablePlane = -6,
    /// The depth image holds no valid reading.
    ErrNoValidDepth = -7,
    /// No support plane could be fitted (give a mask or a table plane).
    ErrNoSupportPlane = -8,
    /// Nothing of the object is left after segmentation (or the mask selects no valid pixel).
    ErrNoObject = -9,
    /// Too few object points for a symmetry search.
    ErrTooFewPoints = -10,
    /// A configuration value is out of range (`sfs_config_types`: an empty or unknown mask;
    /// `sfs_config_parts`, `sfs_config_one_object`: not 0 or 1).
    ErrInvalidConfig = -11,
    /// `sfs_poll` before a successful `sfs_set_input`.
    ErrNotStarted = -12,
    /// The target pixel is outside the image, or the target region is empty or not inside it.
    ErrTargetOutsideImage = -13,
    /// No candidate object region holds the target pixel or overlaps the target region.
    ErrTargetOnNoObject = -14,
    /// A pointer that must not be null is null (or null with a non-zero length).
    ErrNullPointer = -100,
    /// A pointer is not aligned for its type (storage: `sfs_engine_align()`; depth: 2; output: 4).
    ErrBadAlignment = -101,
    /// The storage is smaller than `sfs_engine_size()`.
    ErrTooSmall = -102,
    /// The handle does not point to storage initialised by `sfs_init` (wrong magic number).
    ErrBadHandle = -103,
    /// `sfs_symmetry`: the index is not below `SfsResult.symmetries`.
    ErrOutOfRange = -104,
    /// A size does not fit: width or height above 65 535, or a buffer length whose size in bytes
    /// overflows the address space.
    ErrTooLarge = -105,
    /// Two buffers overlap that must not: the output with depth, mask or the engine's storage,
    /// or depth or mask with the engine's storage.
    ErrOverlap = -106,
    /// `SfsScene.target_kind` is none of `SFS_TARGET_NONE`, `SFS_TARGET_PIXEL`,
    /// `SFS_TARGET_REGION`.
    ErrUnknownTargetKind = -107,
}

impl From<Error> for SfsStatus {
    fn from(e: Error) -> Self {
        match e {
            Error::EmptyImage => SfsStatus::ErrEmptyImage,
            Error::InvalidIntrinsics => SfsStatus::ErrInvalidIntrinsics,
            Error::DepthSizeMismatch { .. } => SfsStatus::ErrDepthSizeMismatch,
            Error::MaskSizeMismatch { .. } => SfsStatus::ErrMaskSizeMismatch,
            Error::InvalidDepthScale => SfsStatus::ErrInvalidDepthScale,
            Error::InvalidTablePlane => SfsStatus::ErrInvalidTablePlane,
            Error::NoValidDepth => SfsStatus::ErrNoValidDepth,
            Error::NoSupportPlane => SfsStatus::ErrNoSupportPlane,
            Error::NoObject => SfsStatus::ErrNoObject,
            Error::TooFewPoints { .. } => SfsStatus::ErrTooFewPoints,
            Error::InvalidConfig { .. } => SfsStatus::ErrInvalidConfig,
            Error::NotStarted => SfsStatus::ErrNotStarted,
            Error::TargetOutsideImage => SfsStatus::ErrTargetOutsideImage,
            Error::TargetOnNoObject => SfsStatus::ErrTargetOnNoObject,
        }
    }
}

/// The eight symmetry types (paper Fig. 5). Bit `1 << type` selects a type in the mask of
/// [`sfs_config_types`].
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SfsSymmetryType {
    /// One mirror plane.
    PlaneReflection = 0,
    /// A half turn about a line.
    LineReflection = 1,
    /// Reflection through a centre point.
    PointReflection = 2,
    /// Continuous rotation about an axis.
    Axial = 3,
    /// Any rotation about a centre point.
    Spherical = 4,
    /// Two orthogonal mirror planes.
    DualPlane = 5,
    /// Three mutually orthogonal mirror planes.
    TriplePlane = 6,
    /// An axis and a mirror plane orthogonal to it.
    AxialPlane = 7,
}

impl From<SymmetryType> for SfsSymmetryType {
    fn from(t: SymmetryType) -> Self {
        match t {
            SymmetryType::PlaneReflection => SfsSymmetryType::PlaneReflection,
            SymmetryType::LineReflection => SfsSymmetryType::LineReflection,
            SymmetryType::PointReflection => SfsSymmetryType::PointReflection,
            SymmetryType::Axial => SfsSymmetryType::Axial,
            SymmetryType::Spherical => SfsSymmetryType::Spherical,
            SymmetryType::DualPlane => SfsSymmetryType::DualPlane,
            SymmetryType::TriplePlane => SfsSymmetryType::TriplePlane,
            SymmetryType::AxialPlane => SfsSymmetryType::AxialPlane,
        }
    }
}
