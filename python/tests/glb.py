"""Reading back the GLB files the tests write."""

import json
import struct


def glb_json(path):
    """The JSON chunk of the GLB file at ``path``."""
    data = path.read_bytes()
    (n,) = struct.unpack("<I", data[12:16])
    return json.loads(data[20:20 + n])
