"""The assertion helper of the tools' ctest scripts (tools/test_*.py): each failed check is printed and counted,
so one run reports every failure, and the script's exit status says whether any failed."""


class Checks:
    def __init__(self, name):
        self.name = name
        self.failures = []

    def __call__(self, cond, what):
        """Record `what` as a failure unless `cond` holds."""
        if not cond:
            self.failures.append(what)
            print("FAIL:", what)

    def status(self):
        """Print the verdict; 0 when every check passed, 1 otherwise (the process's exit status)."""
        print(f"{self.name}:", "FAILED" if self.failures else "passed", f"({len(self.failures)} failures)")
        return 1 if self.failures else 0
