"""One-line usage errors (masonrycli/cli_messages.py): a numeric option given text, or a number with its
unit, says what to write and in which unit the option is read (the units of docs/scenario-format.md and of
the options' help), never converting."""

import pytest

from cli_helpers import assert_one_line_error, invoke

RUN = ("simulate", "wall", "--duration", "0.01", "--no-recording")


@pytest.mark.parametrize(
    "option, value, message",
    [
        ("--dt", "0.001s", "--dt 0.001s: must be a number (write 0.001, in s, without the unit)"),
        ("--dt", "20ms", "--dt 20ms: must be a number (it is read in s: convert 20ms to s and write the number alone)"),
        ("--amp", "1m/s", "--amp 1m/s: must be a number (write 1, in m/s, without the unit)"),
        ("--amp", "3 cm/s", "--amp 3 cm/s: must be a number (it is read in m/s: convert 3 cm/s to m/s"),
        ("--freq", "2Hz", "--freq 2Hz: must be a number (write 2, in Hz, without the unit)"),
        ("--density", "2.5t/m3", "--density 2.5t/m3: must be a number (it is read in kg/m³: convert 2.5t/m3"),
        (
            "--friction",
            "0.6mu",
            '--friction 0.6mu: must be a number (write 0.6, without "mu": this setting has no unit)',
        ),
        ("--record-every", "10steps", '--record-every 10steps: must be an integer (write 10, without "steps"'),
        ("--blocks", "51 blocks", '--blocks 51 blocks: must be an integer (write 51, without "blocks"'),
        ("--dt", "abc", "--dt abc: must be a number"),
    ],
)
def test_a_number_option_given_text_says_what_to_write(option, value, message):
    result = invoke(*RUN, option, value)
    assert_one_line_error(result, message)
    if value == "abc":
        assert result.output.strip().endswith("--dt abc: must be a number")


def test_other_usage_errors_keep_their_message_and_the_help_pointer():
    assert_one_line_error(invoke(*RUN, "--no-such-option"), "No such option", "--help lists the options")
    assert_one_line_error(invoke(*RUN, "--amp", "nan"), "--amp: amplitude = nan: must be a finite number")
