#!/usr/bin/env python3
"""Write verification/external/scenes/cep_tresca.toml (the Chouly–Ern–Pignet Tresca case) and
pentagon_tresca.toml (the same solution at λ = 3 on the Gmsh pentagon); see tresca_py.external.cep."""
from pathlib import Path

from tresca_py.external.cep import pentagon_toml, scene_toml

if __name__ == "__main__":
    for name, text in (("cep_tresca.toml", scene_toml()), ("pentagon_tresca.toml", pentagon_toml())):
        out = Path(__file__).with_name(name)
        out.write_text(text)
        print(f"wrote {out}")
