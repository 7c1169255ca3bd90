"""A class of 12 for the mini course's ``shout`` exercise: five programs, good, bad and
broken, each handed in two or more times (half as a student's folder, half as a bare file
where a test writes them), and the score each program earns. tests/commands/test_batch.py
grades the class; tests/commands/test_scaleout.py shards it as the printed recipes do."""

from __future__ import annotations

from pathlib import Path

COURSE = Path(__file__).parent / "fixtures" / "mini_course"
SOLUTION = (COURSE / "assignments/shout/solution/shouter.py").read_text()
VARIANTS = {
    "good": SOLUTION,
    "lower": SOLUTION.replace("msg.data.upper()", "msg.data"),
    "double": SOLUTION.replace("        self.pub.publish(String(data=msg.data.upper()))",
                               "        for _ in range(2):\n"
                               "            self.pub.publish(String(data=msg.data.upper()))"),
    "syntax": SOLUTION.replace("def on_words(self, msg):", "def on_words(self, msg)"),
    "crash": SOLUTION.replace("super().__init__('shouter')", "raise RuntimeError('boom')"),
}
KINDS = ["good", "lower", "double", "syntax", "crash", "good", "lower", "good", "double",
         "crash", "good", "syntax"]
EXPECTED = {"good": "3", "lower": "2", "double": "2", "syntax": "0", "crash": "0"}
