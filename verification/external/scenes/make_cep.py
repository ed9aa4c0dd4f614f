#!/usr/bin/env python3
"""Write verification/external/scenes/cep_tresca.toml (the Chouly–Ern–Pignet Tresca case; see tresca_py.external.cep)."""
from pathlib import Path

from tresca_py.external.cep import scene_toml

if __name__ == "__main__":
    out = Path(__file__).with_name("cep_tresca.toml")
    out.write_text(scene_toml())
    print(f"wrote {out}")
