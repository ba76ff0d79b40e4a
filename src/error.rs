//! The one error type. Every rejected input maps to a variant; nothing panics.

/// Why a scene was rejected or a search could not run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Error {
    /// Width or height is zero.
    EmptyImage,
    /// A focal length is zero, negative or not finite, or the principal point is not finite.
    InvalidIntrinsics,
    /// The depth slice does not hold `width * height` values.
    DepthSizeMismatch {
        /// `width * height`.
        expected: u32,
        /// The slice's length.
        actual: u32,
    },
    /// The mask slice does not hold `width * height` values.
    MaskSizeMismatch {
        /// `width * height`.
        expected: u32,
        /// The slice's length.
        actual: u32,
    },
    /// The depth scale is not in `(0, [MAX_DEPTH_SCALE](crate::MAX_DEPTH_SCALE)]` (1 m per unit),
    /// or is NaN.
    InvalidDepthScale,
    /// The table plane's normal is not a finite unit vector or its offset is not finite.
    InvalidTablePlane,
    /// The image holds no valid depth reading.
    NoValidDepth,
    /// No support plane could be fitted (needed when neither mask nor table plane is given).
    NoSupportPlane,
    /// Nothing of the object is left after segmentation (or the mask selects no valid pixel).
    NoObject,
    /// Too few object points for a symmetry search.
    TooFewPoints {
        /// Object points sampled.
        found: u32,
        /// The fewest a search accepts.
        needed: u32,
    },
    /// A configuration value is out of range (see [`crate::Config::validate`]): `field` names it,
    /// as a path in [`crate::Config`] (`"model.accept"`).
    InvalidConfig {
        /// The value's path in [`crate::Config`].
        field: &'static str,
    },
    /// `poll` was called before `start`.
    NotStarted,
    /// The target pixel lies outside the image, or the target region is empty or not wholly
    /// inside it.
    TargetOutsideImage,
    /// No candidate object region holds the target pixel or overlaps the target region.
    TargetOnNoObject,
}

impl core::fmt::Display for Error {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Error::EmptyImage => write!(f, "image width or height is zero"),
            Error::InvalidIntrinsics => {
                write!(f, "intrinsics must be finite with positive focal lengths")
            }
            Error::DepthSizeMismatch { expected, actual } => {
                write!(
                    f,
                    "depth image holds {actual} values, width * height is {expected}"
                )
            }
            Error::MaskSizeMismatch { expected, actual } => {
                write!(
                    f,
                    "mask holds {actual} values, width * height is {expected}"
                )
            }
            Error::InvalidDepthScale => {
                write!(f, "depth scale must be positive and at most 1 m per unit")
            }
            Error::InvalidTablePlane => write!(
                f,
                "table plane needs a finite unit normal and a finite offset"
            ),
            Error::NoValidDepth => write!(f, "the depth image has no valid reading"),
            Error::NoSupportPlane => {
                write!(f, "no support plane found (give a mask or a table plane)")
            }
            Error::NoObject => write!(f, "no object left after segmentation"),
            Error::TooFewPoints { found, needed } => {
                write!(f, "{found} object points, a search needs at least {needed}")
            }
            Error::InvalidConfig { field } => write!(f, "configuration value {field} out of range"),
            Error::NotStarted => write!(f, "poll called before start"),
            Error::TargetOutsideImage => write!(
                f,
                "the target pixel or region is not inside the image (or the region is empty)"
            ),
            Error::TargetOnNoObject => {
                write!(
                    f,
                    "no object candidate at the target pixel or in its region"
                )
            }
        }
    }
}

impl core::error::Error for Error {}
