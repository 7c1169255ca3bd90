"""What a node's source says about its design, read from its syntax tree (never run):
which callback group each timer, subscription and service is created in, which executor
spins the node, and which methods call what (who waits on a condition, who notifies it).

The proofs of timer_sync and callback_groups use it to check that their reference
solution is the chapter's design, not merely a program that scores 100%.
"""

from __future__ import annotations

import ast
import dataclasses

GROUP_CLASSES = ("MutuallyExclusiveCallbackGroup", "ReentrantCallbackGroup")
# Where each ``create_*`` call takes its callback, counting positional arguments.
CALLBACK_ARGUMENT = {"create_timer": 1, "create_subscription": 2, "create_service": 2}


@dataclasses.dataclass(frozen=True)
class Entity:
    """A timer, subscription or service the node creates."""

    kind: str            # create_timer, create_subscription, create_service
    args: tuple[str, ...]  # its positional arguments, as source text
    callback: str        # e.g. "self.on_planner"
    group: str | None    # the callback_group argument as source text; None: the default


@dataclasses.dataclass(frozen=True)
class Design:
    entities: tuple[Entity, ...]
    made: dict[str, str]         # what each assignment of a call makes: "x = Foo()" x -> Foo
    spun: tuple[str, ...]        # what is spun: executor variables, or "rclpy.spin"
    methods: dict[str, ast.FunctionDef]

    @property
    def groups(self) -> set[str]:
        """The callback groups the node makes (as the variables that hold them)."""
        return {name for name, kind in self.made.items() if kind in GROUP_CLASSES}

    def entity(self, kind: str, where: str) -> Entity:
        """The one entity of ``kind`` whose arguments include ``where`` (a topic, a
        service name, a period), or whose callback it is."""
        found = [e for e in self.entities
                 if e.kind == kind and (where in e.args or e.callback == where)]
        if len(found) != 1:
            raise LookupError(f"{len(found)} {kind} calls with {where!r}")
        return found[0]

    def alone_in_its_group(self, entity: Entity) -> bool:
        """In a callback group the node made, which nothing else is created in."""
        return entity.group in self.groups and \
            [e.group for e in self.entities].count(entity.group) == 1

    def spins_multithreaded(self) -> bool:
        return any(self.made.get(name) == "MultiThreadedExecutor" for name in self.spun)

    def made_as(self, kind: str) -> set[str]:
        """The variables holding what a call of ``kind`` made (e.g. ``Condition``)."""
        return {name for name, made in self.made.items() if made == kind}

    def calls(self, method: str, attribute: str, on: str) -> bool:
        """Whether method ``method`` calls ``<on>.<attribute>(...)``."""
        body = self.methods.get(method.removeprefix("self."))
        return body is not None and any(
            isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
            and node.func.attr == attribute and ast.unparse(node.func.value) == on
            for node in ast.walk(body))


def read_design(source: str) -> Design:
    tree = ast.parse(source)
    entities: list[Entity] = []
    made: dict[str, str] = {}
    methods: dict[str, ast.FunctionDef] = {}
    spun: list[str] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef):
            methods.setdefault(node.name, node)
        if isinstance(node, ast.Assign) and isinstance(node.value, ast.Call):
            for target in node.targets:
                made[ast.unparse(target)] = _name(node.value.func)
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute):
            method = node.func.attr
            if method in CALLBACK_ARGUMENT:
                keywords = {k.arg: ast.unparse(k.value) for k in node.keywords}
                args = tuple(ast.unparse(a) for a in node.args)
                index = CALLBACK_ARGUMENT[method]
                callback = keywords.get("callback") or (args[index] if len(args) > index
                                                         else "")
                entities.append(Entity(method, args, callback, keywords.get("callback_group")))
            elif method == "spin":
                target = ast.unparse(node.func.value)
                spun.append("rclpy.spin" if target == "rclpy" else target)
    return Design(tuple(entities), made, tuple(spun), methods)


def _name(func: ast.expr) -> str:
    """``Foo`` of ``Foo(...)`` or ``module.Foo(...)``."""
    if isinstance(func, ast.Attribute):
        return func.attr
    return func.id if isinstance(func, ast.Name) else ""
