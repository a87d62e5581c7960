from setuptools import find_packages, setup

package_name = 'multilift_tools'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    package_data={package_name + '.report': ['templates/*.md']},
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='multilift developers',
    maintainer_email='dev@multilift.dev',
    description='Command line, bag tools, plots, Foxglove bridge, sweeps and the reproduction '
                'report of multilift.',
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            'multilift = multilift_tools.cli:main',
        ],
        # the fixtures of multilift_tools.testing in every pytest run of a sourced workspace
        'pytest11': ['multilift = multilift_tools.testing'],
    },
)
