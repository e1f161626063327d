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
