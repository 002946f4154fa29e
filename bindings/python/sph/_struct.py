# SPDX-License-Identifier: MIT
"""Base classes of the generated ctypes structs and opaque types."""
import ctypes
import enum


class Opaque(ctypes.Structure):
    """An opaque C object (sph_context, sph_world, ...): only ever used through pointers."""

    _fields_ = []
    _sph_destroy_ = None


# ctypes stores an int into an integer field or argument modulo 2^bits, silently (a capacity of
# 2^32 + 5 became 5). Every integer the bindings hand to C goes through check_int first.
_INTEGER_CODES = "bBhHiIlLqQ"


def int_range(ctype):
    """(lo, hi) of a ctypes integer type, or None for any other type."""
    code = getattr(ctype, "_type_", None)
    if not isinstance(code, str) or code not in _INTEGER_CODES:
        return None
    bits = 8 * ctypes.sizeof(ctype)
    return (-(1 << (bits - 1)), (1 << (bits - 1)) - 1) if code.islower() else (0, (1 << bits) - 1)


def check_int(ctype, value, what):
    """Raises OverflowError when `value` (an int, or anything with __index__) does not fit the
    ctypes integer type `ctype`; returns the value. Other values pass unchanged (ctypes decides)."""
    bounds = int_range(ctype)
    if bounds is None or isinstance(value, bool) or not hasattr(value, "__index__"):
        return value
    v = value.__index__()
    if not bounds[0] <= v <= bounds[1]:
        kind = ("int" if bounds[0] < 0 else "uint") + str(8 * ctypes.sizeof(ctype))
        raise OverflowError(f"{what}: {v} does not fit {kind} ({bounds[0]}..{bounds[1]})")
    return value


_checked_types = {}


def checked_argtype(ctype):
    """ctype for a function argument, with a from_param that refuses integers that do not fit
    (OverflowError, which ctypes reports as ArgumentError naming the argument's position)."""
    if int_range(ctype) is None:
        return ctype
    checked = _checked_types.get(ctype)
    if checked is None:
        def from_param(cls, value, _base=ctype):
            return _base.from_param(check_int(_base, value, "value"))

        checked = type("Checked_" + ctype.__name__, (ctype,), {"from_param": classmethod(from_param)})
        _checked_types[ctype] = checked
    return checked


def _field_types(cls):
    cached = cls.__dict__.get("_sph_field_types_")
    if cached is None:
        cached = dict(cls._fields_)
        cls._sph_field_types_ = cached
    return cached


def check_real(value, what):
    """float(value) for a real-number argument (an int, a float, a numpy scalar, anything with
    __float__); TypeError for anything else. float() alone parsed strings: step("0.01") ran."""
    if not (hasattr(type(value), "__float__") or hasattr(type(value), "__index__")):
        raise TypeError(f"{what}: expected a real number, got {type(value).__name__}")
    return float(value)


def _convert(ftype, value, what="value"):
    """Accepts tuples/lists/arrays for struct and fixed-array fields; range-checks integers.
    A struct from a sequence takes exactly one value per field (a Vec3 3, a Quat 4): a short
    one was zero-filled (gravity=(0, -9.81) became (0, -9.81, 0), a rotation (0, 0, 1) the
    quaternion (0, 0, 1, 0))."""
    if isinstance(value, ftype):
        return value
    if isinstance(ftype, type) and issubclass(ftype, SphStruct):
        if isinstance(value, dict):
            return ftype(**value)
        names = [f[0] for f in ftype._fields_]
        if isinstance(value, (str, bytes)) or not hasattr(value, "__iter__"):
            raise TypeError(f"{what}: expected {len(names)} values ({', '.join(names)}), got {type(value).__name__}")
        values = list(value)
        if len(values) != len(names):
            raise ValueError(f"{what}: expected {len(names)} values ({', '.join(names)}), got {len(values)}")
        return ftype(*values)
    if isinstance(ftype, type) and issubclass(ftype, ctypes.Array):
        values = list(value)
        if len(values) != ftype._length_:
            raise ValueError(f"{what}: expected {ftype._length_} values, got {len(values)}")
        return ftype(*(check_int(ftype._type_, v, f"{what}[{i}]") for i, v in enumerate(values)))
    return check_int(ftype, value, what)


def _enum_value(enum_cls, value, what):
    """An enum field's value from a member, an int, or a member name in any case ("rk4");
    for IntFlag fields also "a|b" or an iterable of names and members (or'ed together)."""
    is_flag = issubclass(enum_cls, enum.IntFlag)
    if isinstance(value, str):
        names = [n.strip() for n in value.split("|")] if is_flag else [value.strip()]
    elif is_flag and not isinstance(value, int) and hasattr(value, "__iter__"):
        names = list(value)
    else:
        return value
    bits = 0
    for name in names:
        if not isinstance(name, str):
            bits |= int(name)
            continue
        try:
            member = enum_cls[name.upper()]
        except KeyError:
            choices = ", ".join(m.name.lower() for m in enum_cls)
            raise ValueError(f"{what}: {name!r} is not one of {choices}") from None
        if not is_flag:
            return member
        bits |= member
    return enum_cls(bits)


def enum_arg(enum_cls, value, what):
    """A function argument of an enum type (Context's backend, add_source's mode, ...) from a
    member, an int or a member name in any case; a name that is no member raises ValueError
    naming `what` and the accepted names, as the struct fields do (not a bare KeyError)."""
    return enum_cls(_enum_value(enum_cls, value, what))


class UnknownField(AttributeError, TypeError):
    """A field name a struct does not have: an AttributeError (a misspelt attribute) and a
    TypeError (an unexpected keyword argument of World(), add_probe(), ...)."""


class SphStruct(ctypes.Structure):
    """A C struct of sph_c.h with keyword construction and defaults.

    Constructing one calls its C init function (``sph_<name>_init_sized``) when the header has
    one (or the exported default value, e.g. ``sph_transform_identity``), so every field
    starts at the library's default, then applies positional and keyword
    arguments: ``WorldParams(gravity=(0, 0, 0), viscosity=2.0)``. Struct and array fields
    accept tuples, lists and numpy arrays. Unknown field names raise AttributeError (a typo
    never passes silently). Enum fields read back as IntEnum members and also accept member
    names (``WorldDef(integrator="rk4")``); flag fields (``WorldDef.features``,
    ``WorldParams.step_limits``) read back as IntFlags and accept ``"a|b"`` or a list of names.
    """

    _fields_ = []
    _sph_c_name_ = ""  # the C name, e.g. "sph_world_params"
    _sph_size_ = 0  # sizeof() measured by the C compiler when sph_api.json was generated
    _sph_offsets_ = ()  # (field, offsetof()) pairs from the same measurement
    _sph_init_ = None  # name of the exported sized init function, if any
    _sph_assigns_ = {}  # fields the header's inline init sets after the sized init
    _sph_default_ = None  # or an exported function returning the default value (sph_transform_identity)
    _sph_enums_ = {}  # field -> IntEnum class

    def __init__(self, *args, **kwargs):
        super().__init__()
        if self._sph_init_:
            from . import _errors, _loader

            fn = getattr(_loader.library(), self._sph_init_)
            _errors.check(fn(ctypes.byref(self), ctypes.sizeof(self)), self._sph_init_)
            for name, value in self._sph_assigns_.items():
                setattr(self, name, value)
        elif self._sph_default_:
            from . import _loader

            value = getattr(_loader.library(), self._sph_default_)()
            ctypes.memmove(ctypes.byref(self), ctypes.byref(value), ctypes.sizeof(self))
        names = [f[0] for f in self._fields_]
        if len(args) > len(names):
            raise TypeError(f"{type(self).__name__} takes at most {len(names)} positional arguments")
        for name, value in zip(names, args):
            setattr(self, name, value)
        for name, value in kwargs.items():
            setattr(self, name, value)

    def __setattr__(self, name, value):
        ftype = _field_types(type(self)).get(name)
        if ftype is None:
            raise UnknownField(f"{type(self).__name__} has no field {name!r}")
        enums = type(self)._sph_enums_
        if enums and name in enums:
            value = _enum_value(enums[name], value, f"{type(self).__name__}.{name}")
        super().__setattr__(name, _convert(ftype, value, f"{type(self).__name__}.{name}"))

    def __getattribute__(self, name):
        value = super().__getattribute__(name)
        enums = type(self)._sph_enums_
        if enums and name in enums:
            try:
                return enums[name](value)
            except ValueError:
                return value  # a value this binding does not know (a newer library)
        return value

    # Plain value structs (no struct_size: vectors, quaternions, ids) unpack like tuples.
    def __iter__(self):
        if "struct_size" in _field_types(type(self)):
            raise TypeError(f"{type(self).__name__} is not iterable; use to_dict()")
        return (getattr(self, f[0]) for f in self._fields_)

    def __eq__(self, other):
        if type(other) is not type(self):
            return NotImplemented
        return bytes(self) == bytes(other)

    __hash__ = None

    def copy(self):
        """A copy of the struct."""
        return type(self).from_buffer_copy(self)

    def to_dict(self):
        """The fields as a dict; nested structs become dicts, arrays lists, enums IntEnums."""
        out = {}
        for name, ftype in self._fields_:
            value = getattr(self, name)
            if isinstance(value, SphStruct):
                value = value.to_dict()
            elif isinstance(value, ctypes.Array):
                value = [v.to_dict() if isinstance(v, SphStruct) else v for v in value]
            elif isinstance(value, ctypes._Pointer) or isinstance(value, ctypes._CFuncPtr):
                value = ctypes.cast(value, ctypes.c_void_p).value
            out[name] = value
        return out

    def __repr__(self):
        parts = []
        for name, _ in self._fields_:
            value = getattr(self, name)
            if isinstance(value, ctypes.Array):
                value = list(value)
            elif isinstance(value, ctypes._Pointer) or isinstance(value, ctypes._CFuncPtr):
                addr = ctypes.cast(value, ctypes.c_void_p).value
                value = "NULL" if not addr else hex(addr)
                parts.append(f"{name}={value}")
                continue
            if isinstance(value, float):
                value = float(f"{value:.7g}")  # float32 fields: no 0.1 -> 0.10000000149
            parts.append(f"{name}={value!r}")
        return f"{type(self).__name__}({', '.join(parts)})"
