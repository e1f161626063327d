"""The layout of training/: a command module (one with an `if __name__ == "__main__":` block, run with
python -m) holds only its command, and no module under training/ or tests/python imports one; what other
modules need lives in library modules. Tests run commands with subprocess."""
import ast
from pathlib import Path

from conftest import REPO


def module_name(path: Path, root: Path) -> str:
    parts = path.relative_to(root).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def is_command(tree: ast.Module) -> bool:
    return any(isinstance(node, ast.If) and isinstance(node.test, ast.Compare)
               and isinstance(node.test.left, ast.Name) and node.test.left.id == "__name__"
               and any(isinstance(c, ast.Constant) and c.value == "__main__" for c in node.test.comparators)
               for node in tree.body)


def imported_modules(tree: ast.Module, name: str, is_package: bool) -> set[str]:
    """Every module an import statement in `tree` may load: `from a import b` counts as a.b and a."""
    package = name if is_package else name.rpartition(".")[0]
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                parts = package.split(".")
                base = ".".join(parts[:len(parts) - node.level + 1])
                source = f"{base}.{node.module}" if node.module else base
            else:
                source = node.module
            out.add(source)
            out.update(f"{source}.{a.name}" for a in node.names)
    return out


def layout_violations(root: Path, packages: list[str]) -> list[str]:
    """Imports of command modules, and public definitions in them, across the .py files under `packages`
    (folders relative to `root`; a folder that is not a package, like tests/python, is read as top-level modules)."""
    files = {}
    for folder in packages:
        base = root / folder
        top = root if (base / "__init__.py").exists() else base
        for path in sorted(base.rglob("*.py")):
            files[path] = (module_name(path, top), ast.parse(path.read_text(), str(path)))
    commands = {name for name, tree in files.values() if is_command(tree)}
    problems = []
    for path, (name, tree) in files.items():
        for target in sorted(imported_modules(tree, name, path.name == "__init__.py") & commands):
            problems.append(f"{path.relative_to(root)} imports the command module {target}")
        if name in commands:
            for node in tree.body:
                defined = isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef))
                if defined and node.name != "main" and not node.name.startswith("_"):
                    problems.append(f"{path.relative_to(root)} is a command but defines {node.name}; "
                                    "move it to a library module")
    return problems


def test_no_module_imports_a_command():
    assert layout_violations(REPO, ["training", "tests/python"]) == []


def test_every_command_has_a_main():
    for path in sorted((REPO / "training").rglob("*.py")):
        tree = ast.parse(path.read_text())
        if is_command(tree):
            assert any(isinstance(n, ast.FunctionDef) and n.name == "main" for n in tree.body), path


def test_the_check_finds_violations(tmp_path):
    pkg = tmp_path / "training"
    (pkg / "sub").mkdir(parents=True)
    for init in (pkg / "__init__.py", pkg / "sub" / "__init__.py"):
        init.write_text("")
    (pkg / "sub" / "tool.py").write_text('def helper():\n    pass\n\n\ndef main():\n    pass\n\n\n'
                                         'if __name__ == "__main__":\n    main()\n')
    (pkg / "sub" / "lib.py").write_text("from .tool import main\n")
    (pkg / "other.py").write_text("from .sub import tool\nfrom .sub.lib import main\n")
    (tmp_path / "tests").mkdir()
    (tmp_path / "tests" / "test_x.py").write_text("import training.sub.tool\n")
    assert sorted(layout_violations(tmp_path, ["training", "tests"])) == [
        "tests/test_x.py imports the command module training.sub.tool",
        "training/other.py imports the command module training.sub.tool",
        "training/sub/lib.py imports the command module training.sub.tool",
        "training/sub/tool.py is a command but defines helper; move it to a library module",
    ]


# What each part of training/ may import of the others (docs/architecture.md): the pipeline runs one way,
# corpus readers → datasets → networks → one folder per model; shared modules sit beside them.
SHARED = {"paths", "runs", "metrics", "contact_labels", "footlock", "onnx"}
MAY_IMPORT = {
    "paths": set(),
    "runs": {"paths"},
    "mocap": {"paths"},
    "metrics": {"mocap"},
    "contact_labels": {"mocap", "metrics"},
    "footlock": {"mocap", "metrics", "contact_labels"},
    "control": set(),
    "onnx": {"paths"},
    "data": {"mocap", "paths", "metrics", "control"},
    "device": {"data", "paths", "onnx"},
    "models": {"mocap", "data"},
    "generator": {"mocap", "data", "models"} | SHARED,
    "aclstm": {"mocap", "data", "models"} | SHARED,
    "refiner": {"mocap", "data", "models", "generator"} | SHARED,
    "autoencoder": {"mocap", "data", "models"} | SHARED,
    "latent_erd": {"mocap", "data", "models", "autoencoder", "control", "generator"} | SHARED,
    "vae_lstm": {"mocap", "data", "models", "control", "latent_erd"} | SHARED,
    "own": {"mocap", "data", "models", "generator", "aclstm"} | SHARED,
    "style_generator": {"mocap", "data", "models", "generator", "refiner"} | SHARED,
    "bench": {"models"} | SHARED,
    "fixtures": {"mocap", "data", "models", "generator", "refiner", "aclstm", "control", "autoencoder", "latent_erd", "own",
                 "style_generator"} | SHARED,
}


def layering_violations(root: Path) -> list[str]:
    problems = []
    for path in sorted((root / "training").rglob("*.py")):
        name = module_name(path, root)
        parts = name.split(".")
        if len(parts) < 2:
            continue  # training/__init__.py
        part = parts[1]
        allowed = MAY_IMPORT.get(part)
        if allowed is None:
            problems.append(f"{path.relative_to(root)}: training/{part} is not in the layering table")
            continue
        folders = set()
        for target in imported_modules(ast.parse(path.read_text()), name, path.name == "__init__.py"):
            t = target.split(".")
            # Outside training/, the part itself, or a name of `from .. import x` (x is checked as training.x).
            if t[0] == "training" and len(t) > 1 and t[1] != part and t[1] in MAY_IMPORT:
                folders.add(t[1])
        problems += [f"{path.relative_to(root)} (training/{part}) imports training/{f}" for f in sorted(folders - allowed)]
    return problems


def test_training_folders_import_down_the_pipeline_only():
    assert layering_violations(REPO) == []


def test_the_layering_check_finds_violations(tmp_path):
    pkg = tmp_path / "training"
    for sub in ("mocap", "models", "extra"):
        (pkg / sub).mkdir(parents=True)
        (pkg / sub / "__init__.py").write_text("")
    (pkg / "__init__.py").write_text("")
    (pkg / "mocap" / "bvh.py").write_text("from ..models.generator import MixtureLSTM\nfrom .. import metrics\n")
    (pkg / "models" / "net.py").write_text("from ..mocap.skeleton import Skeleton\n")
    (pkg / "extra" / "x.py").write_text("")
    assert layering_violations(tmp_path) == [
        "training/extra/__init__.py: training/extra is not in the layering table",
        "training/extra/x.py: training/extra is not in the layering table",
        "training/mocap/bvh.py (training/mocap) imports training/metrics",
        "training/mocap/bvh.py (training/mocap) imports training/models",
    ]
