"""python -m oceanmc.validation [DIR] [--quick]"""
import sys
from pathlib import Path

from . import main

args = [a for a in sys.argv[1:] if not a.startswith("--")]
sys.exit(main(Path(args[0]) if args else Path("validation"), quick="--quick" in sys.argv))
