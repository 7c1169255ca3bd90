"""The one template environment of every page: the package's templates, everything
escaped, a missing variable an error (never an empty hole in a report), the platform's
``_`` in the language of the moment, and the bidi filters and font stacks pages use."""

from __future__ import annotations

from collections.abc import Iterator

import jinja2
import pytest
from markupsafe import Markup

from autograder.i18n import set_language
from autograder.i18n.templates import FONT_STACK_LATIN, FONT_STACK_UR, environment
from autograder.i18n.text import Text, plain, rich


@pytest.fixture
def english() -> Iterator[None]:
    set_language("en")
    yield
    set_language("en")


def test_one_environment_with_the_packages_templates():
    env = environment()
    assert env is environment()
    for name in ("quiz.html", "quiz_result.html", "quiz_index.html", "report.html"):
        assert env.get_template(name).name == name


def test_everything_is_escaped_and_nothing_missing_passes(english):
    env = environment()
    shown = env.from_string("<p>{{ message }}</p>").render(message="<script>x</script>")
    assert shown == "<p>&lt;script&gt;x&lt;/script&gt;</p>"
    assert env.from_string("{{ html }}").render(html=Markup("<b>ok</b>")) == "<b>ok</b>"
    with pytest.raises(jinja2.UndefinedError):
        env.from_string("<p>{{ mesage }}</p>").render(message="typo'd")
    # Blocks leave no blank lines or indentation of their own behind.
    assert env.from_string("<ul>\n  {% for i in xs %}\n  <li>{{ i }}</li>\n  {% endfor %}\n"
                           "</ul>").render(xs=[1, 2]) == "<ul>\n  <li>1</li>\n  <li>2</li>\n</ul>"


def test_messages_in_the_language_of_the_moment(english):
    template = environment().from_string("{{ _('Submit answers') }}|{{ ngettext("
                                         "'{n} test', '{n} tests', 2) }}")
    assert template.render() == "Submit answers|{n} tests"
    set_language("ur")
    assert template.render().startswith("جوابات جمع کرائیں|")


def test_the_filters_and_font_stacks(english):
    env = environment()
    code = Text("Call `spin()` now", "en")
    assert env.from_string("{{ t|rich }}").render(t=code) == str(rich(code))
    assert '<code dir="ltr">spin()</code>' in env.from_string("{{ t|rich }}").render(t=code)
    assert env.from_string("{{ t|plain }}").render(t=code) == plain(code)
    assert env.from_string("{{ 'a {x}'|bidi(x='<y>') }}").render() == "a &lt;y&gt;"
    assert env.from_string("{{ font_stack_ur }}").render() == FONT_STACK_UR  # not escaped
    assert env.from_string("{{ font_stack_latin }}").render() == FONT_STACK_LATIN
    assert FONT_STACK_UR.startswith('"Noto Nastaliq Urdu"') and FONT_STACK_UR.endswith("serif")
    assert "Nastaliq" not in FONT_STACK_LATIN  # Latin runs never in a face without letters
