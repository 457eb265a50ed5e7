"""FlexBE's own operator input server, flexbe_input's ``input_action_server``, with a person who types.

The server is unchanged: for each InputState request it opens its real Qt window (here on Qt's
offscreen platform) and answers with what was entered. Only the person is scripted: when the
window shows, the next answer (argv) is typed into its line edit and its Submit button clicked.

    python typing_operator.py ANSWER [ANSWER ...]     # the last answer repeats
"""

import os
import sys

os.environ.setdefault('QT_QPA_PLATFORM', 'offscreen')
os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')

from flexbe_input import input_action_server

ANSWERS = sys.argv[1:] or ['1']


class TypingOperatorWindow(input_action_server.InputGUI):
    """The real window; show() is where a person would start typing."""

    def show(self):
        super().show()
        answer = ANSWERS.pop(0) if len(ANSWERS) > 1 else ANSWERS[0]
        print(f'typing {answer!r} into: {self.prompt.text()!r}', flush=True)
        self.line.setText(answer)
        self.button.click()


input_action_server.InputGUI = TypingOperatorWindow

if __name__ == '__main__':
    input_action_server.main(args=[sys.argv[0]])
