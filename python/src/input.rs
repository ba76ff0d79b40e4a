//! The arguments of `complete`, checked and converted into a search's [`Input`]. Every unusable
//! value is a `ValueError` naming the argument; what the library checks itself (focal lengths,
//! the depth scale's range, the table's normal) it reports when the search starts, in its words.

use numpy::{
    AllowTypeChange, PyArray2, PyArrayDescrMethods, PyArrayLike1, PyArrayLike2, PyArrayMethods,
    PyUntypedArray, PyUntypedArrayMethods,
};
use pyo3::conversion::FromPyObjectOwned;
use pyo3::exceptions::PyValueError;
use pyo3::intern;
use pyo3::prelude::*;
use pyo3::types::{PyMapping, PyString};
use shape_from_symmetry::math::Vec3;
use shape_from_symmetry::{Config, Intrinsics, Plane, Rect, SymmetryType, Target, TypeSet};

use crate::search::Input;

/// Work units per poll when the caller names no budget: the command-line tool's default, so that
/// the poll count matches it too (the result does not depend on the budget).
const DEFAULT_BUDGET: u32 = 50_000;

/// The longest `repr` an error message quotes; longer values (arrays) are named by type.
const MAX_QUOTED: usize = 60;

/// The arguments of `complete` as Python passed them.
pub struct Arguments<'a, 'py> {
    pub depth: &'a Bound<'py, PyAny>,
    pub depth_scale: &'a Bound<'py, PyAny>,
    pub intrinsics: &'a Bound<'py, PyAny>,
    pub mask: Option<&'a Bound<'py, PyAny>>,
    pub table: Option<&'a Bound<'py, PyAny>>,
    pub types: Option<&'a Bound<'py, PyAny>>,
    pub parts: Option<&'a Bound<'py, PyAny>>,
    pub budget: Option<&'a Bound<'py, PyAny>>,
    pub target: Option<&'a Bound<'py, PyAny>>,
    pub roi: Option<&'a Bound<'py, PyAny>>,
    pub one_object: Option<&'a Bound<'py, PyAny>>,
}

impl Arguments<'_, '_> {
    /// The search these arguments ask for, or a `ValueError` saying what is wrong with them.
    pub fn parse(&self) -> PyResult<Input> {
        let (depth, size) = depth(self.depth)?;
        let mut config = Config::DEFAULT.with_types(types(self.types)?);
        config.domains.parts = flag(self.parts, "parts")?;
        config.prepare = config
            .prepare
            .with_one_object(flag(self.one_object, "one_object")?);
        Ok(Input {
            depth,
            mask: self.mask.map(|m| mask(m, size)).transpose()?,
            depth_scale: number(self.depth_scale, "depth_scale")?,
            intrinsics: intrinsics(self.intrinsics, size)?,
            table: self.table.map(table).transpose()?,
            config,
            budget: budget(self.budget)?,
            target: target(self.target, self.roi)?,
        })
    }
}

/// The depth image's size in the library's type.
#[derive(Clone, Copy, Debug)]
struct Size {
    height: u16,
    width: u16,
}

impl Size {
    /// The size of an array of `shape` `(height, width)`, if each side fits the library's `u16`.
    fn of([height, width]: [usize; 2]) -> PyResult<Self> {
        match (u16::try_from(height), u16::try_from(width)) {
            (Ok(height), Ok(width)) => Ok(Self { height, width }),
            _ => Err(invalid(format!(
                "depth has shape ({height}, {width}): at most {} pixels a side",
                u16::MAX
            ))),
        }
    }

    fn shape(self) -> [usize; 2] {
        [self.height.into(), self.width.into()]
    }
}

/// `depth`: a 2-D uint16 array, copied row-major (while the search runs without the GIL, another
/// Python thread may write to the caller's array).
fn depth(obj: &Bound<'_, PyAny>) -> PyResult<(Vec<u16>, Size)> {
    let array = ndarray(obj, "depth")?;
    let dtype = array.dtype();
    if !dtype.is_equiv_to(&numpy::dtype::<u16>(obj.py())) {
        return Err(invalid(format!(
            "depth must be a uint16 array, got dtype {dtype}"
        )));
    }
    let size = Size::of(shape_2d(array, "depth")?)?;
    let values = array.cast::<PyArray2<u16>>()?.try_readonly()?;
    Ok((values.as_array().iter().copied().collect(), size))
}

/// `mask`: a boolean or numeric array of the depth image's shape, nonzero = object; copied as
/// the library's `0` / `1` bytes.
fn mask(obj: &Bound<'_, PyAny>, size: Size) -> PyResult<Vec<u8>> {
    let array = ndarray(obj, "mask")?;
    let dtype = array.dtype();
    // Boolean, signed, unsigned, floating: the kinds for which "nonzero" means something.
    if !matches!(dtype.kind(), b'b' | b'i' | b'u' | b'f') {
        return Err(invalid(format!(
            "mask must be a boolean or numeric array, got dtype {dtype}"
        )));
    }
    let shape = shape_2d(array, "mask")?;
    if shape != size.shape() {
        return Err(invalid(format!(
            "mask has shape {}, the depth image {}",
            python_shape(&shape),
            python_shape(&size.shape())
        )));
    }
    let py = obj.py();
    let flags = array.call_method1(intern!(py, "astype"), (numpy::dtype::<bool>(py),))?;
    let flags = flags.cast_into::<PyArray2<bool>>()?.try_readonly()?;
    Ok(flags.as_array().iter().map(|&f| u8::from(f)).collect())
}

/// `intrinsics`: a mapping with `fx`, `fy`, `cx`, `cy` (pixels; `width` and `height`, when
/// present, must be the depth image's), or a 3x3 matrix `K`.
fn intrinsics(obj: &Bound<'_, PyAny>, size: Size) -> PyResult<Intrinsics> {
    let [fx, fy, cx, cy] = match obj.cast::<PyMapping>() {
        Ok(mapping) => from_mapping(mapping, size)?,
        Err(_) => from_matrix(obj)?,
    };
    Ok(Intrinsics {
        width: size.width,
        height: size.height,
        fx,
        fy,
        cx,
        cy,
    })
}

/// `[fx, fy, cx, cy]` of a mapping like a scene file's `intrinsics`.
fn from_mapping(mapping: &Bound<'_, PyMapping>, size: Size) -> PyResult<[f32; 4]> {
    for (key, pixels) in [("width", size.width), ("height", size.height)] {
        if mapping.contains(key)? {
            let name = format!("intrinsics {key}");
            let given: u64 = convert(&mapping.get_item(key)?, &name, "a whole number")?;
            if given != u64::from(pixels) {
                return Err(invalid(format!(
                    "{name} is {given}, the depth image's is {pixels}"
                )));
            }
        }
    }
    let field = |key: &str| {
        let value = mapping.get_item(key).map_err(|_| {
            invalid(format!(
                "intrinsics has no {key}: give fx, fy, cx and cy, or a 3x3 matrix K"
            ))
        })?;
        number(&value, &format!("intrinsics {key}"))
    };
    Ok([field("fx")?, field("fy")?, field("cx")?, field("cy")?])
}

/// `[fx, fy, cx, cy]` of `K = [[fx, 0, cx], [0, fy, cy], [0, 0, 1]]`, given as any array-like.
fn from_matrix(obj: &Bound<'_, PyAny>) -> PyResult<[f32; 4]> {
    const FORM: &str = "[[fx, 0, cx], [0, fy, cy], [0, 0, 1]]";
    let k: PyArrayLike2<'_, f64, AllowTypeChange> = obj.extract().map_err(|_| {
        invalid(format!(
            "intrinsics must be a mapping with fx, fy, cx, cy or a 3x3 matrix K = {FORM}, got {}",
            describe(obj)
        ))
    })?;
    let k = k.as_array();
    let entries: Vec<f64> = k.iter().copied().collect();
    let (&[3, 3], &[fx, skew, cx, k10, fy, cy, k20, k21, k22]) = (k.shape(), &entries[..]) else {
        let shape = python_shape(k.shape());
        return Err(invalid(format!("K must be 3x3, got shape {shape}")));
    };
    // The library's pinhole has no skew and K's last row is fixed.
    if [skew, k10, k20, k21, k22] != [0.0, 0.0, 0.0, 0.0, 1.0] {
        let rows = format!("[[{fx}, {skew}, {cx}], [{k10}, {fy}, {cy}], [{k20}, {k21}, {k22}]]");
        return Err(invalid(format!("K must be {FORM}, got {rows}")));
    }
    Ok([
        finite(fx, "K[0][0] (fx)")?,
        finite(fy, "K[1][1] (fy)")?,
        finite(cx, "K[0][2] (cx)")?,
        finite(cy, "K[1][2] (cy)")?,
    ])
}

/// `table`: `(nx, ny, nz, d)`, the plane `n · X + d = 0` of a scene file's `table_plane`, as the
/// library's `n · X = -d` (normalised, as the command-line tool reads a scene file).
fn table(obj: &Bound<'_, PyAny>) -> PyResult<Plane> {
    let wrong = || {
        invalid(format!(
            "table must be 4 numbers (nx, ny, nz, d), got {}",
            describe(obj)
        ))
    };
    let values: PyArrayLike1<'_, f64, AllowTypeChange> = obj.extract().map_err(|_| wrong())?;
    let values: Vec<f64> = values.as_array().iter().copied().collect();
    let &[nx, ny, nz, d] = &values[..] else {
        return Err(wrong());
    };
    let normal = Vec3::new(
        finite(nx, "table nx")?,
        finite(ny, "table ny")?,
        finite(nz, "table nz")?,
    );
    Plane::new(normal, -finite(d, "table d")?).ok_or_else(|| {
        invalid("table normal (nx, ny, nz) is zero: it must point away from the table")
    })
}

/// `types`: symmetry type names (`SymmetryType::from_name`); `None` = all eight.
fn types(obj: Option<&Bound<'_, PyAny>>) -> PyResult<TypeSet> {
    let Some(obj) = obj else {
        return Ok(TypeSet::ALL);
    };
    let not_a_list = || {
        invalid(format!(
            "types must be a list of type names, got {}",
            describe(obj)
        ))
    };
    let mut types = Vec::new();
    for item in items(obj, not_a_list)? {
        let name: String = convert(&item, "each of types", "a type name")?;
        types.push(SymmetryType::from_name(&name).ok_or_else(|| unknown_type(&name))?);
    }
    if types.is_empty() {
        return Err(invalid("types is empty: name at least one type"));
    }
    Ok(TypeSet::of(&types))
}

fn unknown_type(name: &str) -> PyErr {
    let known: Vec<&str> = SymmetryType::ALL.iter().map(|t| t.name()).collect();
    invalid(format!(
        "unknown symmetry type {name:?}: expected one of {}",
        known.join(", ")
    ))
}

/// A flag argument named `name` (`parts`: search part symmetries too; `one_object`: nothing
/// touches the object), `False` when not given.
fn flag(obj: Option<&Bound<'_, PyAny>>, name: &str) -> PyResult<bool> {
    obj.map_or(Ok(false), |obj| convert(obj, name, "True or False"))
}

/// `budget`: work units per poll, positive.
fn budget(obj: Option<&Bound<'_, PyAny>>) -> PyResult<u32> {
    let expected = "a positive whole number of work units per poll";
    match obj
        .map(|obj| convert::<u32>(obj, "budget", expected))
        .transpose()?
    {
        None => Ok(DEFAULT_BUDGET),
        Some(0) => Err(invalid(format!("budget must be {expected}, got 0"))),
        Some(budget) => Ok(budget),
    }
}

/// `target` or `roi`, not both: a pixel `(u, v)` on the object or a region `(x, y, w, h)` around
/// it, in pixels (the library checks them against the image).
fn target(
    target: Option<&Bound<'_, PyAny>>,
    roi: Option<&Bound<'_, PyAny>>,
) -> PyResult<Option<Target>> {
    match (target, roi) {
        (None, None) => Ok(None),
        (Some(_), Some(_)) => Err(invalid(
            "target and roi exclude each other: name the object by a pixel (u, v) or by a \
             region (x, y, w, h)",
        )),
        (Some(obj), None) => {
            let [u, v] = pixels(obj, "target", ["u", "v"])?;
            Ok(Some(Target::Pixel { u, v }))
        }
        (None, Some(obj)) => {
            let [u0, v0, width, height] = pixels(obj, "roi", ["x", "y", "w", "h"])?;
            if width == 0 || height == 0 {
                return Err(invalid(format!(
                    "roi is {width}x{height} pixels: its width and height must be positive"
                )));
            }
            Ok(Some(Target::Region(Rect {
                u0,
                v0,
                width,
                height,
            })))
        }
    }
}

/// A sequence of `N` pixel coordinates or sizes, whole numbers from 0 to 65 535, named `names`.
fn pixels<const N: usize>(
    obj: &Bound<'_, PyAny>,
    name: &str,
    names: [&str; N],
) -> PyResult<[u16; N]> {
    let form = format!("({})", names.join(", "));
    let wrong = || {
        invalid(format!(
            "{name} must be {N} whole numbers {form}, got {}",
            describe(obj)
        ))
    };
    let items = items(obj, wrong)?;
    if items.len() != N {
        return Err(wrong());
    }
    let mut values = [0; N];
    for ((value, item), part) in values.iter_mut().zip(&items).zip(names) {
        let whole: i128 = item.extract().map_err(|_| wrong())?;
        *value = u16::try_from(whole).map_err(|_| {
            invalid(format!(
                "{name} {part} must be a whole number from 0 to {}, got {whole}",
                u16::MAX
            ))
        })?;
    }
    Ok(values)
}

/// The items of an iterable argument, or `wrong()` for another value or a string (iterable too,
/// but its letters are no items).
fn items<'py>(
    obj: &Bound<'py, PyAny>,
    wrong: impl Fn() -> PyErr,
) -> PyResult<Vec<Bound<'py, PyAny>>> {
    if obj.is_instance_of::<PyString>() {
        return Err(wrong());
    }
    obj.try_iter().map_err(|_| wrong())?.collect()
}

/// `obj` as a numpy array of any dtype and shape.
fn ndarray<'a, 'py>(
    obj: &'a Bound<'py, PyAny>,
    name: &str,
) -> PyResult<&'a Bound<'py, PyUntypedArray>> {
    obj.cast::<PyUntypedArray>().map_err(|_| {
        invalid(format!(
            "{name} must be a numpy array, got {}",
            describe(obj)
        ))
    })
}

/// `(height, width)` of a 2-D array.
fn shape_2d(array: &Bound<'_, PyUntypedArray>, name: &str) -> PyResult<[usize; 2]> {
    match *array.shape() {
        [height, width] => Ok([height, width]),
        ref shape => Err(invalid(format!(
            "{name} must be 2-D (height, width), got shape {}",
            python_shape(shape)
        ))),
    }
}

/// A finite number as `f32`, the library's float type.
fn number(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<f32> {
    finite(convert(obj, name, "a number")?, name)
}

/// `value` as `f32`, unless it is NaN, infinite, or beyond `f32`'s range.
fn finite(value: f64, name: &str) -> PyResult<f32> {
    let single = value as f32;
    if single.is_finite() {
        Ok(single)
    } else {
        Err(invalid(format!(
            "{name} must be a finite number within ±{:e}, got {value}",
            f32::MAX
        )))
    }
}

/// `obj` as a `T`, or a `ValueError`: "NAME must be EXPECTED, got VALUE".
fn convert<'py, T: FromPyObjectOwned<'py>>(
    obj: &Bound<'py, PyAny>,
    name: &str,
    expected: &str,
) -> PyResult<T> {
    obj.extract()
        .map_err(|_| invalid(format!("{name} must be {expected}, got {}", describe(obj))))
}

/// A value for an error message: its `repr` if short, else its type.
fn describe(obj: &Bound<'_, PyAny>) -> String {
    match obj.repr() {
        Ok(repr) if repr.to_string().chars().count() <= MAX_QUOTED => repr.to_string(),
        _ => match obj.get_type().name() {
            Ok(name) => format!("a value of type {name}"),
            Err(_) => "an object of unknown type".into(),
        },
    }
}

/// A shape as Python writes it: `(240, 320)`, `(5,)`, `()`.
fn python_shape(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => {
            let sides: Vec<String> = shape.iter().map(ToString::to_string).collect();
            format!("({})", sides.join(", "))
        }
    }
}

fn invalid(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}
