"""The pipeline's Nominal of a document object's shape, and the face roles the nominal
objects (DemoBlade, CadModel) keep as a property map."""

import json

from ...cad.nominal import nominal_from_shape
from ...core.errors import InputError
from .base import shape_signature


def roles_to_map(roles):
    """Face roles {role: [face index, ...]} as an App::PropertyMap value."""
    return {name: " ".join(str(int(i)) for i in faces) for name, faces in (roles or {}).items()}


def roles_from_map(mapping):
    """The face roles an App::PropertyMap value written by roles_to_map holds."""
    return {name: [int(i) for i in text.split()] for name, text in dict(mapping).items()}


_NOMINAL_CACHE = {}


def nominal_of(obj):
    """The pipeline's Nominal of a document object's shape (any Part feature; face roles from
    its FaceRoles when it has them). Cached by shape content: building one samples every face."""
    shape = obj.Shape
    if shape.isNull() or not shape.Faces:
        raise InputError("%s: the nominal has no faces" % obj.Label)
    roles = roles_from_map(obj.FaceRoles) if "FaceRoles" in obj.PropertiesList else None
    key = (shape_signature(shape), json.dumps(roles, sort_keys=True))
    if key not in _NOMINAL_CACHE:
        _NOMINAL_CACHE.clear()
        _NOMINAL_CACHE[key] = nominal_from_shape(shape, roles=roles or None)
    return _NOMINAL_CACHE[key]
