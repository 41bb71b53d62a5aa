from wbfriction.cli import main

main()
