"""Print, one per line, the uv arguments that install from where pip is configured to (its
index URL, extra index URLs, find-links and constraint files, from `pip config list`, the
environment's PIP_* variables included), so `uv pip install` resolves as `pip install` does.
Run by scripts/setup with the venv's Python."""
import shlex
import subprocess
import sys

FLAGS = {'index-url': '--index-url', 'extra-index-url': '--extra-index-url',
         'find-links': '--find-links', 'constraint': '--constraint'}


def main() -> None:
    listed = subprocess.run([sys.executable, '-m', 'pip', 'config', 'list'],
                            capture_output=True, text=True, check=False).stdout
    seen = set()
    for line in listed.splitlines():
        key, _, value = line.partition('=')
        flag = FLAGS.get(key.rsplit('.', 1)[-1])
        if flag is None:
            continue
        for item in shlex.split(value.strip().strip("'\"")):
            if (flag, item) not in seen:
                seen.add((flag, item))
                print(flag)
                print(item)


if __name__ == '__main__':
    main()
