"""A PEP 517 backend that zips one module into a wheel (no setuptools/wheel needed offline)."""

import base64
import hashlib
import zipfile
from pathlib import Path

NAME, DIST, VERSION, MODULE = "pkmlab-demo-family", "pkmlab_demo_family", "0.1", \
    "pkmlab_demo_family.py"
ENTRY = "[pkmlab.families]\nlegs6 = pkmlab_demo_family:Legs6\n"


def _record(name, data):
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return f"{name},sha256={digest},{len(data)}"


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    here = Path(__file__).parent
    info = f"{DIST}-{VERSION}.dist-info"
    files = {MODULE: (here / MODULE).read_bytes(),
             f"{info}/METADATA": f"Metadata-Version: 2.1\nName: {NAME}\nVersion: {VERSION}\n"
                                 .encode(),
             f"{info}/WHEEL": b"Wheel-Version: 1.0\nGenerator: wheel_backend\n"
                              b"Root-Is-Purelib: true\nTag: py3-none-any\n",
             f"{info}/entry_points.txt": ENTRY.encode()}
    record = [_record(n, d) for n, d in files.items()] + [f"{info}/RECORD,,"]
    files[f"{info}/RECORD"] = ("\n".join(record) + "\n").encode()
    wheel = f"{DIST}-{VERSION}-py3-none-any.whl"
    with zipfile.ZipFile(Path(wheel_directory) / wheel, "w") as z:
        for n, d in files.items():
            z.writestr(n, d)
    return wheel


def get_requires_for_build_wheel(config_settings=None):
    return []
